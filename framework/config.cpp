#include "config.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <map>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "particles.hpp"
#include "registry.hpp"
#include "stage_repeat.hpp"

namespace loam {

// GCC 12 at -O3 reports a false -Wrestrict in the std::string operator+ inlined in these schema
// builders (as in schema.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"

/// One entry of `stages:` (docs/stages.md). Its changes act at the stage's start; a key that is
/// absent leaves that part of the model as the previous stage had it.
Schema stage_schema() {
  Schema st;
  st.text("name", "stage name (summary.json stages[], messages)").required();
  st.real("duration", "s", "simulated time of the stage").positive();
  st.choice("until", {"static"},
            "static: the stage ends once the model is at rest (every particle moving slower "
            "than static_speed for static_window), or after max_time as not static");
  st.real("max_time", "s", "with until: static, the time after which the stage ends as not static")
      .positive();
  st.real("static_speed", "m/s",
          "with until: static: the model is at rest while every particle moves slower than "
          "this, |x(n+1) - x(n)| / dt (it bounds the kinetic energy of the motion: E_k <= M v^2 "
          "/ 2)")
      .def("1e-5")
      .positive();
  st.real("static_window", "s",
          "with until: static: how long the speeds must stay below static_speed (0: the time a "
          "P-wave takes to cross the grid's longest side at the stage's start)")
      .def("0")
      .min(0);
  st.choice("if_not_static", {"stop", "continue"},
            "what follows a stage that did not reach static: stop the run there (its record says "
            "so; the remaining stages are listed as not run) or go on")
      .def("stop");
  st.plugin_list("loads", "load",
                 "the loads from this stage on, replacing the previous stage's (an empty list "
                 "removes them all); their time (ramp_time) counts from the stage's start");
  st.plugin_list("boundaries", "boundary",
                 "the boundary conditions from this stage on, replacing the previous ones");
  st.plugin("damping", "damping",
            "damping from this stage on (`none` switches it off); absent: unchanged");
  {
    Schema m;
    m.text("body", "the body whose material changes").required();
    m.plugin("material", "material",
             "its material from this stage on: the keys given replace the body's current ones "
             "(checked by the material's schema); with another `type:`, the whole material")
        .required();
    st.section_list("materials", m,
                    "material changes at the stage's start (e.g. phi 42 -> 28 deg, or elastic "
                    "during a gravity stage and Mohr-Coulomb after it)");
  }
  st.string_list("activate",
                 "bodies whose particles join the run at the stage's start (construction: a body "
                 "with `active: false`, its initial stress from its `stress:`)")
      .def("[]");
  st.string_list("deactivate",
                 "bodies whose particles leave the run at the stage's start (excavation)")
      .def("[]");
  st.string_list(
        "reset",
        "what is reset at the stage's start: displacement (the reference of the "
        "displacement output and of max_displacement becomes the current position), "
        "velocity (every phase), plastic_strain (the output plastic_strain_eq; no material "
        "state: a softened material stays softened)")
      .def("[]");
  {
    Schema o;
    o.integer("every_steps", "write a frame every N steps").min(1);
    o.real("every_time", "s", "write a frame every T seconds of simulated time").positive();
    st.section("output", o, "frame interval from this stage on (absent: unchanged)");
  }
  st.check([](const Params& p, Diagnostics& d) {
    const bool until = p.has("until");
    if (until == p.has("duration"))
      d.error(p.where(), p.path(), "give exactly one of 'duration' or 'until: static'");
    if (until && !p.has("max_time"))
      d.error(p.where("until"), p.path("until"),
              "until: static needs max_time (the time after which the stage counts as not "
              "static)");
    if (!until && p.has("max_time"))
      d.error(p.where("max_time"), p.path("max_time"), "max_time belongs to until: static");
    const std::vector<std::string> resets{"displacement", "velocity", "plastic_strain"};
    const auto& r = p.strings("reset");
    for (size_t i = 0; i < r.size(); ++i)
      if (std::find(resets.begin(), resets.end(), r[i]) == resets.end())
        d.error(p.where("reset", i), p.path("reset") + "." + std::to_string(i),
                "unknown reset '" + r[i] + "'" + suggest(r[i], resets, "valid values are"));
  });
  return st;
}

/// `strength_reduction:` (docs/strength_reduction.md): after the stages, the factor of safety by
/// bisection on the strength reduction factor F, each trial from the last stage's static state.
Schema strength_reduction_schema() {
  Schema r;
  r.vector("factors", "-",
           "[F_low, F_high]: the bracket the factor of safety is searched in; F_low must leave "
           "the model static and F_high must not (both are tried first)",
           2)
      .positive();
  r.real("tolerance", "-", "the search ends when the bracket is this narrow (absolute, in F)")
      .def("0.01")
      .positive();
  r.string_list("bodies",
                "the bodies whose strength is reduced (default: every body whose material has a "
                "strength: Material::reduced)")
      .def("[]");
  r.real("max_time", "s",
         "simulated time of a trial: a trial not static by then has failed (the slope is still "
         "moving)")
      .positive();
  r.real("static_speed", "m/s",
         "a trial is static once every particle moves slower than this for static_window "
         "(|x(n+1) - x(n)| / dt, as for a stage with until: static)")
      .def("1e-5")
      .positive();
  r.real("static_window", "s",
         "how long the speeds must stay below static_speed (0: the time a P-wave takes to cross "
         "the grid's longest side)")
      .def("0")
      .min(0);
  r.real("failure_displacement", "m",
         "a trial fails at once when a particle has moved this far from the static state "
         "(default: only the time limit decides)")
      .positive();
  r.check([](const Params& p, Diagnostics& d) {
    if (!p.has("factors")) return;
    const auto& f = p.vec("factors");
    if (f.size() == 2 && f[1] <= f[0])
      d.error(p.where("factors"), p.path("factors"),
              "factors = [" + format_number(f[0]) + ", " + format_number(f[1]) +
                  "]: F_high must exceed F_low");
  });
  return r;
}
#pragma GCC diagnostic pop

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
    b.boolean("active",
              "false: the body's particles are generated but join the run only when a stage "
              "activates it (construction)")
        .def("true");
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
  s.plugin("contact", "contact",
           "contact between bodies: each body in contact moves on its own velocity field and "
           "the law exchanges momentum where they meet (absent: one velocity field, bodies "
           "stick where they touch)");
  {
    Schema t;
    t.real("end", "s", "simulated end time (a run with `stages:` gives each stage's time instead)")
        .positive();
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
    s.section("time", t, "time integration (with stages: without `end`)");
  }
  {
    Schema o;
    o.integer("every_steps", "write a frame every N steps").min(1);
    o.real("every_time", "s", "write a frame every T seconds of simulated time").positive();
    o.string_list(
         "fields",
         "particle fields to write besides position (an unknown name lists the available "
         "ones); derived when written: displacement (since the last displacement reset) and "
         "strain_magnitude (sqrt(eps:eps) of the logarithmic strain 1/2 ln(F F^T) since that "
         "reset; it requests the deformation gradient F)")
        .def("[velocity, stress]");
    o.plugin("writer", "writer", "output format").def(reg.default_of("writer"));
    o.integer("history_every",
              "write energies and momentum to history.csv every N steps (0: at frames)")
        .def("0")
        .min(0);
    o.boolean("energy_balance",
              "add the energy balance to history.csv and summary.json: material, damping and "
              "transfer dissipation, the work of loads and boundary conditions, the energy "
              "particles carry in and out, and the balance (docs/energy_balance.md; costs a few "
              "% of the step)")
        .def("false");
    o.integer("history_digits",
              "significant digits of the numbers in history.csv (17: every bit of a double)")
        .def("12")
        .min(6)
        .max(17);
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
    p.vector("node_near", "m", "the grid node nearest to this point");
    p.string_list("fields", "fields to record").def("[position, velocity]");
    p.integer("every_steps", "sample every N steps").def("1").min(1);
    s.section_list("probes", p, "time series at a particle or a node, written as CSV");
  }
  s.plugin("verify", "reference", "analytic reference; its error metrics go to summary.json");
  s.section_list("stages", stage_schema(),
                 "a staged analysis (docs/stages.md): the run goes through these stages in order, "
                 "each applying its changes at its start and ending after its duration or once "
                 "static; without it the run is one stage of time.end. A stage with "
                 "repeat: {times: N, step: {key.path: increment}} stands for N copies of it, "
                 "NAME_1 .. NAME_N, each stepped value v + k increment (docs/stages.md, Repeated "
                 "stages)");
  s.section("strength_reduction", strength_reduction_schema(),
            "a factor of safety by strength reduction after the last stage "
            "(docs/strength_reduction.md): c and tan(phi) divided by F, bisection on F, each "
            "trial from the last stage's static state");
  s.check([](const Params& p, Diagnostics& d) {
    const bool staged = !p.list("stages").empty();
    const Params& t = p.section("time");
    if (staged && t.has("end"))
      d.error(t.where("end"), t.path("end"),
              "a run with stages takes its time from them (each stage's duration or max_time): "
              "remove time.end");
    if (!staged && !t.present("end"))
      d.error(t.where(), t.path(), "missing required key 'end' (simulated end time, s)");
    if (p.given("strength_reduction")) {  // its keys are required only when it is given
      const Params& r = p.section("strength_reduction");
      if (!staged || !p.list("stages").back().has("until"))
        d.error(r.where(), r.path(),
                "strength reduction starts from a static state: the last stage must be `until: "
                "static` (e.g. the gravity stage)");
      for (const char* k : {"factors", "max_time"})
        if (!r.present(k))
          d.error(r.where(), r.path(k),
                  std::string("missing required key '") + k + "' (" +
                      (k[0] == 'f' ? "[F_low, F_high]" : "the time limit of a trial, s") + ")");
    }
  });
  {
    Schema n;
    n.integer("sort_every", "sort particles by cell every N steps (locality, thread partition)")
        .def("20")
        .min(1);
    n.real("mass_tolerance", "kg",
           "nodes with less mass get no acceleration (f / m is unbounded there) but keep their "
           "points' mean velocity p / m")
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
  s.string_list("accept_warnings",
                "key paths (as a warning prints them, e.g. bodies.0.material.E) whose implausible "
                "values are meant: their warnings are not shown");
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

/// stages[].materials[].material gives only what changes: its keys go over the body's material
/// (of the same type) here, so that the material's own schema checks the whole of it. The keys
/// keep their places in the file (the stage's where given, the body's otherwise).
void merge_stage_materials(YAML::Node root) {
  if (!root["stages"] || !root["stages"].IsSequence() || !root["bodies"] ||
      !root["bodies"].IsSequence())
    return;
  for (size_t s = 0; s < root["stages"].size(); ++s) {
    YAML::Node changes = root["stages"][s].IsMap() ? root["stages"][s]["materials"] : YAML::Node();
    if (!changes || !changes.IsSequence()) continue;
    for (size_t c = 0; c < changes.size(); ++c) {
      YAML::Node change = changes[c];
      if (!change.IsMap() || !change["body"] || !change["body"].IsScalar() || !change["material"] ||
          !change["material"].IsMap())
        continue;
      YAML::Node base;
      for (size_t b = 0; b < root["bodies"].size(); ++b) {
        YAML::Node body = root["bodies"][b];
        if (body.IsMap() && body["name"] && body["name"].IsScalar() &&
            body["name"].Scalar() == change["body"].Scalar())
          base = body["material"];
      }
      if (!base) continue;  // an unknown body: reported when the model is built
      YAML::Node given = change["material"];
      const std::string base_type = base.IsScalar() ? base.Scalar()
                                    : base.IsMap() && base["type"] && base["type"].IsScalar()
                                        ? base["type"].Scalar()
                                        : "";
      if (given["type"] && given["type"].IsScalar() && given["type"].Scalar() != base_type)
        continue;  // another model: the whole material is given
      YAML::Node merged(YAML::NodeType::Map);
      if (base.IsScalar()) merged["type"] = base;
      if (base.IsMap())
        for (auto it = base.begin(); it != base.end(); ++it) merged[it->first] = it->second;
      // A key the body's material has already is found by its text (node keys compare by
      // identity in yaml-cpp: indexing with the stage's key node would add a second entry, and
      // the body's value, read first, would win); a new key keeps its node (its place).
      const YAML::Node& lookup = merged;
      for (auto it = given.begin(); it != given.end(); ++it) {
        if (it->first.IsScalar() && lookup[it->first.Scalar()])
          merged[it->first.Scalar()] = it->second;
        else
          merged[it->first] = it->second;
      }
      change["material"] = merged;
    }
  }
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
  expand_repeated_stages(root, file, diag);
  merge_stage_materials(root);
  Schema schema = config_schema();
  // Stress fields have 3 + D(D-1)/2 components (Voigt, with the out-of-plane normal stress).
  for (auto& p : schema.params)
    if (p.key == "bodies")
      for (auto& q : p.section->params)
        if (q.key == "stress") q.plugin_components = stress_components(ctx.dimension);
  out.params = validate(root, schema, "", Location{file, 1, 1}, ctx, diag);
  out.warnings = diag.warnings();
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

std::string run_warnings(const LoadedConfig& config, const Diagnostics& found) {
  Diagnostics all;
  std::vector<std::string> warned;
  for (const auto* list : {&config.warnings, &found.warnings()})
    for (const Diagnostic& w : *list) {
      all.warning(w.where, w.path, w.message);
      warned.push_back(w.path);
    }
  const Params& p = config.params;
  if (!p.has("accept_warnings")) return all.format_warnings();
  const std::vector<std::string>& accepted = p.strings("accept_warnings");
  all.accept_warnings(accepted);
  for (size_t i = 0; i < accepted.size(); ++i)
    if (std::find(warned.begin(), warned.end(), accepted[i]) == warned.end())
      all.warning(p.where("accept_warnings", i), "accept_warnings." + std::to_string(i),
                  "'" + accepted[i] + "' has no warning to accept" +
                      suggest(accepted[i], warned, "keys with warnings are"));
  return all.format_warnings();
}

}  // namespace loam
