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
