#pragma once
#include <map>
#include <string>
#include <utility>
#include <vector>
// Reference (analytic solution) plugin interface, selected by `verify:`. It samples the run as it
// goes and returns named error metrics, written to summary.json.
#include <map>
#include <string>

namespace loam {

template <int D>
class Simulation;
class Diagnostics;

template <int D>
class Reference {
 public:
  static constexpr const char* kind = "reference";
  virtual ~Reference() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Called at the end of every step.
  virtual void sample(Simulation<D>&) {}
  virtual std::map<std::string, double> metrics(Simulation<D>&) = 0;
  /// A time series the reference recorded (column name, values; the first column is usually
  /// the time), or empty: written to summary.json (verify.series) and to verify.csv.
  virtual std::vector<std::pair<std::string, std::vector<double>>> series() const { return {}; }
  /// Checkpoints (output.checkpoint): the plugin's accumulated state as doubles, restored
  /// bit for bit on --resume. false: it has none implemented yet, and a checkpointed run with
  /// it is refused (a silently lost state would break the resumed run's results).
  virtual bool save_state(std::vector<double>&) const { return false; }
  virtual void restore_state(const std::vector<double>&) {}
};

}  // namespace loam
