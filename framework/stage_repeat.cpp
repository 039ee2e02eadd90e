#include "stage_repeat.hpp"

#include <cstdio>
#include <cstdlib>
#include <vector>

#include "params.hpp"

namespace loam {

namespace {

Location place(const YAML::Node& node, const std::string& file) {
  if (!node.IsDefined() || node.Mark().line < 0) return Location{file, 1, 1};
  return Location{file, node.Mark().line + 1, node.Mark().column + 1};
}

/// "loads.0.value" -> {"loads", "0", "value"}.
std::vector<std::string> split_path(const std::string& path) {
  std::vector<std::string> parts;
  size_t start = 0;
  for (size_t dot = path.find('.');; dot = path.find('.', start)) {
    parts.push_back(path.substr(start, dot - start));
    if (dot == std::string::npos) break;
    start = dot + 1;
  }
  return parts;
}

/// The node at `path` under `node`, or an undefined node.
YAML::Node find(const YAML::Node& node, const std::vector<std::string>& path, size_t level = 0) {
  if (level == path.size()) return node;
  if (node.IsMap()) {
    for (auto it = node.begin(); it != node.end(); ++it)
      if (it->first.IsScalar() && it->first.Scalar() == path[level])
        return find(it->second, path, level + 1);
  } else if (node.IsSequence()) {
    char* end = nullptr;
    const long i = std::strtol(path[level].c_str(), &end, 10);
    if (*end == '\0' && i >= 0 && size_t(i) < node.size())
      return find(node[size_t(i)], path, level + 1);
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

/// A copy of `node` that shares its children (and their places in the file) except along
/// `path`, whose containers are copied and whose end is `leaf`: the other copies keep theirs.
YAML::Node replaced(const YAML::Node& node, const std::vector<std::string>& path, size_t level,
                    const YAML::Node& leaf) {
  if (level == path.size()) return leaf;
  if (node.IsMap()) {
    YAML::Node copy(YAML::NodeType::Map);
    for (auto it = node.begin(); it != node.end(); ++it)
      copy[it->first] = it->first.IsScalar() && it->first.Scalar() == path[level]
                            ? replaced(it->second, path, level + 1, leaf)
                            : it->second;
    return copy;
  }
  YAML::Node copy(YAML::NodeType::Sequence);
  for (size_t i = 0; i < node.size(); ++i)
    copy.push_back(std::to_string(i) == path[level] ? replaced(node[i], path, level + 1, leaf)
                                                    : node[i]);
  return copy;
}

bool as_number(const YAML::Node& n, double& v) {
  if (!n.IsScalar()) return false;
  char* end = nullptr;
  v = std::strtod(n.Scalar().c_str(), &end);
  return !n.Scalar().empty() && *end == '\0';
}

/// A number as YAML text that reads back to the same double.
std::string exact_text(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

/// value + k * step for a number or a list of numbers of the same length; false if the shapes
/// do not match.
bool stepped(const YAML::Node& value, const YAML::Node& step, int k, YAML::Node& out) {
  double v, s;
  if (as_number(value, v) && as_number(step, s)) {
    out = YAML::Node(exact_text(v + k * s));
    return true;
  }
  if (!value.IsSequence() || !step.IsSequence() || value.size() != step.size()) return false;
  out = YAML::Node(YAML::NodeType::Sequence);
  for (size_t i = 0; i < value.size(); ++i) {
    YAML::Node e;
    if (!stepped(value[i], step[i], k, e)) return false;
    out.push_back(e);
  }
  out.SetStyle(YAML::EmitterStyle::Flow);
  return true;
}

/// Check stage s's repeat; the number of copies, 0 after an error.
int check_repeat(const YAML::Node& stage, const YAML::Node& repeat, const std::string& at,
                 const std::string& file, Diagnostics& diag) {
  if (!repeat.IsMap()) {
    diag.error(place(repeat, file), at, "expected a map {times: N, step: {key.path: increment}}");
    return 0;
  }
  bool ok = true;
  for (auto it = repeat.begin(); it != repeat.end(); ++it)
    if (!it->first.IsScalar() || (it->first.Scalar() != "times" && it->first.Scalar() != "step")) {
      diag.error(place(it->first, file), at + "." + it->first.as<std::string>(""),
                 "unknown key; valid keys are: times, step");
      ok = false;
    }
  double times = 0;
  if (!repeat["times"] || !as_number(repeat["times"], times) || times < 1 ||
      times != double(long(times))) {
    diag.error(place(repeat["times"] ? repeat["times"] : repeat, file), at + ".times",
               "expected the number of copies, an integer >= 1");
    ok = false;
  }
  const YAML::Node step = repeat["step"];
  if (step && !step.IsMap()) {
    diag.error(place(step, file), at + ".step", "expected a map {key.path: increment}");
    ok = false;
  }
  if (step && step.IsMap())
    for (auto it = step.begin(); it != step.end(); ++it) {
      const std::string key = it->first.as<std::string>("");
      const YAML::Node value = find(stage, split_path(key));
      YAML::Node probe;
      if (!value.IsDefined()) {
        diag.error(place(it->first, file), at + ".step." + key,
                   "the stage has no value at '" + key + "' to step");
        ok = false;
      } else if (!stepped(value, it->second, 0, probe)) {
        diag.error(place(it->second, file), at + ".step." + key,
                   "the increment must have the shape of the stepped value (a number, or a list "
                   "of as many numbers)");
        ok = false;
      }
    }
  if (!stage["name"] || !stage["name"].IsScalar()) ok = false;  // reported by validation
  return ok ? int(times) : 0;
}

/// Copy k of a stage: its name NAME_(k+1), each stepped value v + k * increment, no repeat.
YAML::Node stage_copy(const YAML::Node& stage, const YAML::Node& step, int k) {
  YAML::Node copy(YAML::NodeType::Map);
  for (auto it = stage.begin(); it != stage.end(); ++it) {
    const std::string key = it->first.as<std::string>("");
    if (key == "repeat") continue;
    copy[it->first] =
        key == "name" ? YAML::Node(it->second.Scalar() + "_" + std::to_string(k + 1)) : it->second;
  }
  if (step)
    for (auto it = step.begin(); it != step.end(); ++it) {
      const std::vector<std::string> path = split_path(it->first.as<std::string>(""));
      YAML::Node value;
      stepped(find(copy, path), it->second, k, value);
      copy = replaced(copy, path, 0, value);
    }
  return copy;
}

}  // namespace

void expand_repeated_stages(YAML::Node root, const std::string& file, Diagnostics& diag) {
  if (!root.IsMap() || !root["stages"] || !root["stages"].IsSequence()) return;
  const YAML::Node stages = root["stages"];
  YAML::Node expanded(YAML::NodeType::Sequence);
  bool any = false;
  for (size_t s = 0; s < stages.size(); ++s) {
    const YAML::Node stage = stages[s];
    const YAML::Node repeat = stage.IsMap() ? stage["repeat"] : YAML::Node();
    if (!repeat) {
      expanded.push_back(stage);
      continue;
    }
    any = true;
    const int times =
        check_repeat(stage, repeat, "stages." + std::to_string(s) + ".repeat", file, diag);
    if (times == 0) {  // reported: the stage stays, without its repeat
      YAML::Node kept(YAML::NodeType::Map);
      for (auto it = stage.begin(); it != stage.end(); ++it)
        if (it->first.as<std::string>("") != "repeat") kept[it->first] = it->second;
      expanded.push_back(kept);
    }
    for (int k = 0; k < times; ++k) expanded.push_back(stage_copy(stage, repeat["step"], k));
  }
  if (any) root["stages"] = expanded;
}

}  // namespace loam
