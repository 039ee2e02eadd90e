// No damping: what a stage names to switch the damping of an earlier stage off
// (`damping: none`, docs/stages.md).
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class NoDamping : public Damping<D> {
 public:
  static constexpr const char* name = "none";
  static constexpr const char* summary = "no damping (switches a stage's damping off)";
  static Schema schema() { return {}; }
  explicit NoDamping(const Params&) {}
  void apply(Simulation<D>&, const NodeForces&) override {}
  bool runs_on_ranks() const override { return true; }
};

LOAM_REGISTER(Damping, NoDamping)

}  // namespace loam
