#pragma once
// `loam compare SWEEP.yaml`: run every combination of --set overrides of a base config and
// collect speed and error in compare.csv (+ pareto.png when Python/matplotlib are available).
#include <string>

namespace loam {

struct CompareOptions {
  std::string sweep_file;
  std::string out_dir;  // default results/<sweep name>
  int threads = 0;      // per variant; 0: the sweep's `threads`, else all cores
  bool quiet = false;
};

/// Returns the exit code: 0 when every variant ran (even if some failed), 2 for a bad sweep file.
int run_compare(const CompareOptions& options);

}  // namespace loam
