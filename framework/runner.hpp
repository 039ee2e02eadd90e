#pragma once
// Running a validated configuration: output directory handling, frames, probes, history,
// progress, stability checks and summary.json. Exit codes: 0 ok, 2 bad input, 3 unstable run.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "config.hpp"

namespace loam {

struct RunOptions {
  std::vector<std::string> overrides;
  std::string out_dir;  // default results/<config name>
  bool overwrite = false;
  int threads = 0;  // 0: all available
  bool quiet = false;
  bool write_output = true;  // false: no directory, no files (benchmarks)
  long max_steps = -1;       // stop after this many steps (benchmarks)
  bool profile = false;      // time each phase of the step (summary: profile_seconds)
  /// Continue the run whose output directory (its newest checkpoint) or checkpoint file this
  /// names; the output goes on in that directory.
  std::string resume;
  /// Print errors and progress (false on every MPI rank but the first: each rank runs the same
  /// loop and would say the same).
  bool report = true;
};

struct RunResult {
  int exit_code = 0;
  nlohmann::json summary;
  std::string message;   // errors to print (already formatted)
  std::string warnings;  // warnings to print (run_warnings), when the model was built
};

/// Validate and run a file; prints diagnostics and progress. Returns the exit code.
int run_file(const std::string& file, const RunOptions& options);
/// Run an already loaded configuration (tests, benchmarks).
RunResult run_config(const LoadedConfig& config, const RunOptions& options);
/// Validate only (`loam check`): builds the model but runs no step.
RunResult check_config(const LoadedConfig& config);

std::string loam_version();
std::string git_commit();

}  // namespace loam
