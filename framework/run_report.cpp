#include "run_report.hpp"

#include <cmath>
#include <set>

#include <spdlog/fmt/fmt.h>

namespace loam {

namespace {

using nlohmann::json;

double number(const json& j, const char* key) {
  return j.contains(key) && j[key].is_number() ? j[key].get<double>() : std::nan("");
}

/// "runout_ratio 2.64 against 2.48 (Lube et al. 2005), +6.5 %".
std::string comparison_text(const json& c) {
  const double value = number(c, "value"), ref = number(c, "reference_value");
  std::string text = fmt::format("{} {:.4g} against {:.4g} ({})", c.value("measured", ""), value,
                                 ref, c.value("source", ""));
  if (std::isfinite(value) && std::isfinite(ref) && ref != 0)
    text += fmt::format(", {:+.3g} %", 100 * (value / ref - 1));
  return text;
}

/// The verify metrics named *error that no comparison shows, as "name value, ...".
std::string other_errors(const json& verify) {
  std::set<std::string> shown;
  if (verify.contains("comparisons"))
    for (const auto& c : verify["comparisons"]) shown.insert(c.value("measured", ""));
  std::string text;
  for (const auto& [key, x] : verify.items()) {
    const bool error = key.size() >= 5 && key.compare(key.size() - 5, 5, "error") == 0;
    if (!error || !x.is_number() || shown.count(key)) continue;
    text += fmt::format("{}{} {:.3g}", text.empty() ? "" : ", ", key, x.get<double>());
  }
  return text;
}

/// "name status at 2.31 s" per stage; a run of three or more consecutive stages with one
/// status as "first ... last status (N stages, to 43.5 s)". Joined into lines of ~100 characters.
std::vector<std::string> stage_lines(const json& stages) {
  std::vector<std::string> items;
  for (size_t k = 0; k < stages.size();) {
    const std::string status = stages[k].value("status", "?");
    size_t e = k + 1;
    while (e < stages.size() && stages[e].value("status", "?") == status) ++e;
    const json& last = stages[e - 1];
    const std::string at =
        last.contains("end_time") ? fmt::format(" at {:.4g} s", number(last, "end_time")) : "";
    if (e - k >= 3) {
      items.push_back(fmt::format("{} ... {} {} ({} stages, to{})", stages[k].value("name", "?"),
                                  last.value("name", "?"), status, e - k,
                                  at.empty() ? " the end" : at.substr(3)));
    } else {
      for (size_t j = k; j < e; ++j)
        items.push_back(stages[j].value("name", "?") + " " + status +
                        (stages[j].contains("end_time")
                             ? fmt::format(" at {:.4g} s", number(stages[j], "end_time"))
                             : ""));
    }
    k = e;
  }
  std::vector<std::string> lines;
  std::string line = "stages: ";
  for (size_t i = 0; i < items.size(); ++i) {
    if (i > 0 && line.size() + items[i].size() > 98) lines.push_back(line + ";"), line = "        ";
    line += (line.back() == ' ' ? "" : "; ") + items[i];
  }
  lines.push_back(line);
  return lines;
}

/// "particles.xdmf, history.csv, summary.json": the frames' index per particle set when frames
/// were written, then the history and the summary.
std::string written_files(const json& summary) {
  std::string files;
  if (summary.value("frames", 0L) > 0 && summary.contains("sets"))
    for (const auto& [set, record] : summary["sets"].items()) files += set + ".xdmf, ";
  return files + "history.csv, summary.json";
}

std::string strength_reduction_text(const json& srf) {
  std::string text = "strength reduction: " + srf.value("status", "?");
  if (srf.contains("factor_of_safety"))
    text += fmt::format(", factor of safety {:.4g}", number(srf, "factor_of_safety"));
  if (srf.contains("factor_of_safety_bracket")) {
    const json& b = srf["factor_of_safety_bracket"];
    auto end = [](const json& x) {
      return x.is_number() ? fmt::format("{:.5g}", x.get<double>()) : "-";
    };
    text += " [" + end(b[0]) + ", " + end(b[1]) + "]";
  }
  if (srf.contains("undecided_factor"))
    text += fmt::format(" (the trial F = {:.5g} was still moving at max_time)",
                        number(srf, "undecided_factor"));
  return text;
}

}  // namespace

std::vector<std::string> run_report(const json& summary, const std::string& out_dir) {
  std::vector<std::string> lines;
  const std::string status = summary.value("status", "?");
  lines.push_back(out_dir.empty() ? "status " + status + " (no output written)"
                                  : "status " + status + ", output in " + out_dir + " (" +
                                        written_files(summary) + ")");
  const json& verify = summary.contains("verify") ? summary["verify"] : json::object();
  if (verify.contains("comparisons"))
    for (const auto& c : verify["comparisons"])
      lines.push_back(verify.value("reference", "verify") + ": " + comparison_text(c));
  if (const std::string errors = other_errors(verify); !errors.empty())
    lines.push_back(verify.value("reference", "verify") + ": " + errors);
  if (summary.contains("stages"))
    for (const std::string& l : stage_lines(summary["stages"])) lines.push_back(l);
  if (summary.contains("strength_reduction"))
    lines.push_back(strength_reduction_text(summary["strength_reduction"]));
  return lines;
}

std::string run_report_line(const json& summary, const std::string& out_dir) {
  std::string line = fmt::format(
      "loam: {}: {}, {} steps, {:.3g} s wall", out_dir.empty() ? "(no output)" : out_dir,
      summary.value("status", "?"), summary.value("steps", 0L), number(summary, "wall_seconds"));
  const json& verify = summary.contains("verify") ? summary["verify"] : json::object();
  if (verify.contains("comparisons"))
    for (const auto& c : verify["comparisons"]) line += "; " + comparison_text(c);
  if (summary.contains("factor_of_safety"))
    line += fmt::format("; factor of safety {:.4g}", number(summary, "factor_of_safety"));
  return line;
}

}  // namespace loam
