#include "config.hpp"

#include <yaml-cpp/yaml.h>
#include <map>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "particles.hpp"
#include "registry.hpp"

namespace loam {

Schema config_schema() {
  const Registry& reg = Registry::instance();
  Schema s;
  s.string_list("plugins", "shared libraries with out-of-tree plugins, loaded before validation");
  {
    Schema g;
    g.vector("origin", "m", "lower corner of the grid").def("0").scalar_ok();
    g.vector("extent", "m",
             "size of the grid along each axis; its length sets the dimension (1, 2 or 3)")
        .required()
        .positive();
    g.vector("cell_size", "m",
             "cell size (one number or one per axis); the extent must be a multiple")
        .required()
        .positive()
        .scalar_ok();
    s.section("grid", g, "background grid").required();
  }
  // Defaults are whatever plugin declared itself the default of its kind; the core names none.
  s.plugin("shape_function", "shape_function", "interpolation between particles and nodes")
      .def(reg.default_of("shape_function"));
  s.plugin("scheme", "scheme", "what one explicit step does (mixture formulation, update order)")
      .def(reg.default_of("scheme"));
  s.vector("gravity", "m/s^2", "gravitational acceleration").def("0").scalar_ok();
  {
    Schema b;
    b.text("name", "body name, used by loads, references and output").required();
    b.text("set",
           "the particle set of the scheme the body's particles belong to (default: the "
           "scheme's first set; `loam plugins` lists each scheme's sets)");
    b.plugin("generator", "generator",
             "region filled with particles at t = 0 (none: the body starts empty and gets its "
             "particles from a source)");
    b.integer("particles_per_cell", "particles per cell along each axis").def("2").min(1).max(10);
    b.plugin("material", "material", "constitutive model of the body").required();
    b.plugin("velocity", "field", "initial velocity (a list is a constant)").components(kDimension);
    b.plugin("stress", "field", "initial Cauchy stress, Voigt xx yy zz xy yz xz (tension positive)")
        .components(-100);  // resolved to the stress component count below
    {
      Schema i;
      i.text("field",
             "a scalar particle field the run has after set-up (e.g. pore_pressure of a "
             "two-phase scheme)")
          .required();
      i.plugin("value", "field", "its initial value (a list is a constant)")
          .components(1)
          .required();
      b.section_list("initial", i,
                     "initial values of further scalar particle fields, set after the scheme "
                     "and materials have created them (e.g. a hydrostatic pore pressure)");
    }
    s.section_list("bodies", b, "bodies of particles").required();
  }
  {
    Schema ps;
    ps.text("name", "selection name, referred to by loads (traction `selection:`)").required();
    ps.vector("min", "m", "lower corner of the selection box").required();
    ps.vector("max", "m", "upper corner of the selection box").required();
    s.section_list("selections", ps, "named selections of particles (boxes, at t = 0)");
  }
  s.plugin_list("boundaries", "boundary", "boundary conditions on grid faces");
  s.plugin_list("loads", "load", "external loads");
  s.plugin_list("sources", "source", "particle sources: inflow of a body's particles");
  s.plugin_list("sinks", "sink", "particle sinks: outflow, removing particles");
  s.plugin("damping", "damping", "numerical damping (e.g. to reach a static state)");
  {
    Schema t;
    t.real("end", "s", "simulated end time").required().positive();
    t.real("cfl", "-", "Courant number: dt = cfl * cell / (wave speed + particle speed)")
        .def("0.5")
        .above(0)
        .max(1);
    t.real("dt", "s", "fixed time step (overrides cfl)").positive();
    t.integer("max_steps",
              "step budget: a run whose first stable time step would need more steps to reach "
              "`end` is rejected before it starts, and a run whose time step collapses stops "
              "when it reaches the budget (exit 3)")
        .def("100000000")
        .min(1);
    t.real("min_dt_ratio", "-",
           "a stable time step below this fraction of the first step's stops the run (exit 3): "
           "the wave or particle speed has exploded (e.g. USL with linear shape functions at a "
           "node of tiny mass), and the run would otherwise crawl until max_steps")
        .def("1e-6")
        .above(0)
        .below(1);
    s.section("time", t, "time integration").required();
  }
  {
    Schema o;
    o.integer("every_steps", "write a frame every N steps").min(1);
    o.real("every_time", "s", "write a frame every T seconds of simulated time").positive();
    o.string_list(
         "fields",
         "particle fields to write besides position (an unknown name lists the available ones)")
        .def("[velocity, stress]");
    o.plugin("writer", "writer", "output format").def(reg.default_of("writer"));
    o.integer("history_every",
              "write energies and momentum to history.csv every N steps (0: at frames)")
        .def("0")
        .min(0);
    Schema c;
    c.integer("every_steps", "write a checkpoint every N steps").min(1);
    c.real("every_wall_seconds", "s", "write a checkpoint every T seconds of wall time").positive();
    c.integer("keep", "how many of the newest checkpoints to keep (default 2)").min(1);
    c.check([](const Params& p, Diagnostics& d) {
      if (p.has("keep") && !p.has("every_steps") && !p.has("every_wall_seconds"))
        d.error(p.where(), p.path(), "give every_steps or every_wall_seconds (or both)");
    });
    o.section("checkpoint", c,
              "checkpoints (checkpoint_<step>.h5 in the output directory): loam run --resume "
              "DIR continues from the newest, bit for bit");
    s.section("output", o, "output of particle frames");
  }
  {
    Schema p;
    p.text("name", "probe name; written to probe_<name>.csv").required();
    p.vector("particle_near", "m", "follow the particle nearest to this point at t = 0");
    p.text("set", "with particle_near: the particle set to search (default: the scheme's first)");
    p.vector("node", "-", "grid node indices (i, j, k)");
    p.string_list("fields", "fields to record").def("[position, velocity]");
    p.integer("every_steps", "sample every N steps").def("1").min(1);
    s.section_list("probes", p, "time series at a particle or a node, written as CSV");
  }
  s.plugin("verify", "reference", "analytic reference; its error metrics go to summary.json");
  {
    Schema n;
    n.integer("sort_every", "sort particles by cell every N steps (locality, thread partition)")
        .def("20")
        .min(1);
    n.real("mass_tolerance", "kg", "nodes with less mass get zero velocity (guards division)")
        .def("1e-12")
        .positive();
    n.integer("check_every", "check particles for NaN/inf and leaving the grid every N steps")
        .def("10")
        .min(1);
    n.boolean("keep_last_good",
              "keep a copy of the particles at each passed check, written as the last regular "
              "frame (and, with output.checkpoint, checkpoint) when a later step fails (the "
              "failed state goes to a 'failed' frame); false saves the copy's memory (about the "
              "particles' own)")
        .def("true");
    s.section("numerics", n, "numerical controls");
  }
  return s;
}

namespace {

/// yaml-cpp's parser message, with a hint where its wording is parser jargon.
std::string yaml_message(const YAML::Exception& e) {
  if (e.msg == YAML::ErrorMsg::END_OF_SEQ_FLOW)
    return e.msg + " (a '[' is not closed or a ',' is missing)";
  if (e.msg == YAML::ErrorMsg::END_OF_MAP_FLOW)
    return e.msg + " (a '{' is not closed or a ',' is missing)";
  return e.msg;
}

/// Every key given twice in one map, at its second (third, ...) place: yaml-cpp keeps both
/// pairs but looks up the first, so the later value would be dropped silently.
void report_duplicate_keys(const YAML::Node& n, const std::string& path, const std::string& file,
                           int line_offset, int column_offset, Diagnostics& diag) {
  if (n.IsSequence()) {
    for (size_t i = 0; i < n.size(); ++i)
      report_duplicate_keys(n[i], path.empty() ? std::to_string(i) : path + "." + std::to_string(i),
                            file, line_offset, column_offset, diag);
    return;
  }
  if (!n.IsMap()) return;
  std::map<std::string, YAML::Mark> seen;
  for (auto it = n.begin(); it != n.end(); ++it) {
    const std::string key = it->first.IsScalar() ? it->first.Scalar() : "";
    const std::string sub = path.empty() ? key : path + "." + key;
    const YAML::Mark m = it->first.Mark();
    auto [first, fresh] = seen.emplace(key, m);
    if (!fresh)
      diag.error(Location{file, m.line + 1 + line_offset,
                          m.column + 1 + (m.line == 0 ? column_offset : 0)},
                 sub,
                 "duplicate key '" + key + "' (first given at line " +
                     std::to_string(first->second.line + 1 + line_offset) + ", column " +
                     std::to_string(first->second.column + 1 +
                                    (first->second.line == 0 ? column_offset : 0)) +
                     "): each key may appear once in a map");
    report_duplicate_keys(it->second, sub, file, line_offset, column_offset, diag);
  }
}

/// Apply `a.b.c=value` to the YAML tree; list elements are addressed by index (bodies.0.name).
bool apply_override(YAML::Node root, const std::string& arg, const std::string& label,
                    Diagnostics& diag, std::string& path_out) {
  auto eq = arg.find('=');
  if (eq == std::string::npos || eq == 0) {
    diag.error(Location{label, 1, 1}, arg, "expected --set path.to.key=value");
    return false;
  }
  std::string path = arg.substr(0, eq), text = arg.substr(eq + 1);
  path_out = path;
  YAML::Node value;
  try {
    value = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    diag.error(Location{label, 1, int(eq) + 2 + std::max(0, e.mark.column)}, path,
               "malformed YAML value: " + yaml_message(e));
    return false;
  }
  const size_t errors = diag.errors().size();
  report_duplicate_keys(value, path, label, 0, int(eq) + 1, diag);
  if (diag.errors().size() != errors) return false;
  std::vector<std::string> parts;
  std::stringstream ss(path);
  for (std::string p; std::getline(ss, p, '.');) parts.push_back(p);
  // Walk with an explicit chain of nodes: yaml-cpp's operator[] on a map creates entries.
  std::vector<YAML::Node> chain{root};
  for (size_t i = 0; i + 1 < parts.size(); ++i) {
    YAML::Node cur = chain.back();
    const std::string& k = parts[i];
    bool is_index = !k.empty() && k.find_first_not_of("0123456789") == std::string::npos;
    if (cur.IsSequence()) {
      if (!is_index || std::stoul(k) >= cur.size()) {
        diag.error(Location{label, 1, 1}, path,
                   "'" + k + "' is not an index of the list (it has " + std::to_string(cur.size()) +
                       " entries)");
        return false;
      }
      chain.push_back(cur[std::stoul(k)]);
    } else if (cur.IsMap()) {
      if (!cur[k] || cur[k].IsNull()) cur[k] = YAML::Node(YAML::NodeType::Map);
      // A plugin given by name alone (`shape_function: cpdi`) becomes {type: cpdi} so that
      // its parameters can be overridden too.
      if (cur[k].IsScalar()) {
        YAML::Node m(YAML::NodeType::Map);
        m["type"] = cur[k].Scalar();
        cur[k] = m;
      }
      chain.push_back(cur[k]);
    } else {
      diag.error(Location{label, 1, 1}, path,
                 "cannot set '" + parts[i + 1] + "' inside '" +
                     join({parts.begin(), parts.begin() + long(i) + 1}, ".") +
                     "', which is not a map");
      return false;
    }
  }
  YAML::Node parent = chain.back();
  const std::string& last = parts.back();
  if (parent.IsSequence()) {
    bool is_index = last.find_first_not_of("0123456789") == std::string::npos;
    if (!is_index || std::stoul(last) >= parent.size()) {
      diag.error(Location{label, 1, 1}, path, "'" + last + "' is not an index of the list");
      return false;
    }
    parent[std::stoul(last)] = value;
  } else {
    parent[last] = value;
  }
  return true;
}

int detect_dimension(const YAML::Node& root) {
  YAML::Node e =
      root.IsMap() && root["grid"] && root["grid"].IsMap() ? root["grid"]["extent"] : YAML::Node();
  if (e && e.IsSequence() && e.size() >= 1 && e.size() <= 3) return int(e.size());
  return 0;
}

/// Overrides and out-of-tree plugin libraries: what every YAML input file gets before
/// validation. Returns false if the root is not a map (reported).
bool prepare_tree(YAML::Node& root, const std::string& file,
                  const std::vector<std::string>& overrides, ValidationContext& ctx,
                  Diagnostics& diag, const char* not_a_map) {
  ctx.file = file;
  report_duplicate_keys(root, "", file, 0, 0, diag);
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) {
    diag.error(Location{file, root.Mark().line + 1, root.Mark().column + 1}, "", not_a_map);
    return false;
  }
  for (size_t i = 0; i < overrides.size(); ++i) {
    std::string label = "<--set " + overrides[i] + ">", path;
    if (apply_override(root, overrides[i], label, diag, path)) ctx.overrides[path] = label;
  }
  // Out-of-tree plugins register before anything names them.
  if (root["plugins"] && root["plugins"].IsSequence())
    for (size_t i = 0; i < root["plugins"].size(); ++i) {
      YAML::Node p = root["plugins"][i];
      std::string where = "plugins." + std::to_string(i);
      if (!p.IsScalar()) continue;  // reported by validation
      std::filesystem::path lib(p.Scalar());
      if (lib.is_relative()) lib = std::filesystem::path(file).parent_path() / lib;
      Location loc = location_of(p, where, ctx, Location{file, 1, 1});
      if (!std::filesystem::exists(lib)) {
        diag.error(loc, where, "plugin library not found: " + lib.string());
        continue;
      }
      std::string err = load_plugin_library(lib.string());
      if (!err.empty()) diag.error(loc, where, err);
    }
  return true;
}

LoadedConfig validate_tree(YAML::Node root, const std::string& file,
                           const std::vector<std::string>& overrides, Diagnostics& diag) {
  LoadedConfig out;
  out.file = file;
  out.name = std::filesystem::path(file).stem().string();
  ValidationContext ctx;
  if (!prepare_tree(root, file, overrides, ctx, diag,
                    "a run file must be a map of keys (grid, bodies, time, ...)"))
    return out;
  out.dimension = detect_dimension(root);
  ctx.dimension = out.dimension ? out.dimension : 2;
  if (!out.dimension && root["grid"] && root["grid"].IsMap() && root["grid"]["extent"] &&
      root["grid"]["extent"].IsSequence()) {
    YAML::Node e = root["grid"]["extent"];
    diag.error(
        location_of(e, "grid.extent", ctx, Location{file, 1, 1}), "grid.extent",
        "the grid needs 1, 2 or 3 components (one per dimension), got " + std::to_string(e.size()));
  }
  Schema schema = config_schema();
  // Stress fields have 3 + D(D-1)/2 components (Voigt, with the out-of-plane normal stress).
  for (auto& p : schema.params)
    if (p.key == "bodies")
      for (auto& q : p.section->params)
        if (q.key == "stress") q.plugin_components = stress_components(ctx.dimension);
  out.params = validate(root, schema, "", Location{file, 1, 1}, ctx, diag);
  return out;
}

Location parse_error_location(const YAML::Exception& e, const std::string& file) {
  return Location{file, std::max(0, e.mark.line) + 1, std::max(0, e.mark.column) + 1};
}

}  // namespace

LoadedConfig load_config_text(const std::string& text, const std::string& label,
                              const std::vector<std::string>& overrides, Diagnostics& diag) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    diag.error(parse_error_location(e, label), "", "malformed YAML: " + yaml_message(e));
    LoadedConfig out;
    out.file = label;
    return out;
  }
  return validate_tree(root, label, overrides, diag);
}

namespace {

/// The text of a file, or "" with an error in diag.
bool read_file(const std::string& file, const char* what, std::string& text, Diagnostics& diag) {
  std::ifstream in(file);
  if (!in) {
    diag.error(Location{file, 1, 1}, "",
               std::string("cannot open the ") + what + ": " +
                   (std::filesystem::exists(file) ? "permission denied" : "no such file"));
    return false;
  }
  std::stringstream ss;
  ss << in.rdbuf();
  text = ss.str();
  return true;
}

}  // namespace

Params load_yaml_file(const std::string& file, const std::vector<std::string>& overrides,
                      const Schema& schema, int dimension, Diagnostics& diag) {
  std::string text;
  if (!read_file(file, "input file", text, diag)) return {};
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    diag.error(parse_error_location(e, file), "", "malformed YAML: " + yaml_message(e));
    return {};
  }
  ValidationContext ctx;
  ctx.dimension = dimension;
  if (!prepare_tree(root, file, overrides, ctx, diag, "the input file must be a map of keys"))
    return {};
  return validate(root, schema, "", Location{file, 1, 1}, ctx, diag);
}

LoadedConfig load_config(const std::string& file, const std::vector<std::string>& overrides,
                         Diagnostics& diag) {
  std::string text;
  if (!read_file(file, "run file", text, diag)) {
    LoadedConfig out;
    out.file = file;
    return out;
  }
  return load_config_text(text, file, overrides, diag);
}

}  // namespace loam
