#pragma once
// What `loam run` tells at the end of a run that finished (docs/runs.md, What a run tells): where
// its output is, its status, each comparison of its reference beside the value it is compared
// with, the other error metrics, each stage's outcome and the factor of safety. Read from the
// run's summary.json content, so the terminal and the file cannot disagree.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace loam {

/// The report's lines after the run's "done:" line; `out_dir` empty when nothing was written.
std::vector<std::string> run_report(const nlohmann::json& summary, const std::string& out_dir);

/// The report in one line (--quiet): output, status, steps, wall time and the comparisons.
std::string run_report_line(const nlohmann::json& summary, const std::string& out_dir);

}  // namespace loam
