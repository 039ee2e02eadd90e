// A test-only out-of-tree plugin (tests/test_checkpoint.cpp): a reference that keeps a running
// state (the largest particle speed seen) but does not implement save_state, as a plugin
// written before checkpoints existed would. A checkpointed run with it must be refused at
// set-up: resuming it would silently restart its state from zero. Nor does it declare
// runs_on_ranks: under mpirun it is refused where the file names it (tests/test_mpi_runs.cpp).
#include <algorithm>
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam_test_plugin {

template <int D>
class PeakSpeed : public loam::Reference<D> {
 public:
  static constexpr const char* name = "test_peak_speed";
  static constexpr const char* summary = "test-only: the largest particle speed (no save_state)";
  static loam::Schema schema() { return {}; }
  explicit PeakSpeed(const loam::Params&) {}
  void sample(loam::Simulation<D>& sim) override { peak_ = std::max(peak_, sim.max_speed); }
  std::map<std::string, double> metrics(loam::Simulation<D>&) override {
    return {{"peak_speed", peak_}};
  }

 private:
  double peak_ = 0;
};

LOAM_REGISTER(Reference, PeakSpeed)

}  // namespace loam_test_plugin

extern "C" __attribute__((visibility("default"))) int loam_plugin_abi_version() {
  return loam::kPluginAbiVersion;
}
