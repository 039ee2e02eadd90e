#pragma once
// Reference (analytic solution) plugin interface, selected by `verify:`. It samples the run as it
// goes and returns named error metrics, written to summary.json.
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace loam {

template <int D>
class Simulation;
class Diagnostics;

/// When a reference that records a time series samples: at the first step, then each time the
/// run passes a multiple of `every` seconds; restart() makes the next call due (the end of the
/// run is always sampled). `next` is its whole state (a reference checkpoints it).
struct SampleClock {
  double every = 0, next = 0;
  bool due(double t) {
    if (t < next * (1 - 1e-12) - 1e-15) return false;
    next = (std::floor(t / every + 1e-9) + 1) * every;
    return true;
  }
  void restart() { next = 0; }
};

/// Two metrics of a reference shown side by side at the end of a run (framework/run_report.hpp,
/// summary.json verify.comparisons): the measured value and the value it is compared with, both
/// keys of metrics(), and where that value comes from (a paper by author and year, a solution).
struct Comparison {
  std::string measured, reference, source;
};

template <int D>
class Reference {
 public:
  static constexpr const char* kind = "reference";
  virtual ~Reference() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Called at the end of every step.
  virtual void sample(Simulation<D>&) {}
  virtual std::map<std::string, double> metrics(Simulation<D>&) = 0;
  /// The pairs of metrics() to show side by side, given its values; default none.
  virtual std::vector<Comparison> comparisons(const std::map<std::string, double>&) const {
    return {};
  }
  /// A time series the reference recorded (column name, values; the first column is usually
  /// the time), or empty: written to summary.json (verify.series) and to verify.csv.
  virtual std::vector<std::pair<std::string, std::vector<double>>> series() const { return {}; }
  /// Checkpoints (output.checkpoint): the plugin's accumulated state as doubles, restored
  /// bit for bit on --resume. false: it has none implemented yet, and a checkpointed run with
  /// it is refused (a silently lost state would break the resumed run's results).
  virtual bool save_state(std::vector<double>&) const { return false; }
  virtual void restore_state(const std::vector<double>&) {}
  /// Whether its metrics are over all ranks under mpirun (docs/parallel.md): each rank calls
  /// metrics() and sample() with its own particles, and the plugin reduces over sim.ranks.
  virtual bool runs_on_ranks() const { return false; }
};

}  // namespace loam
