// Local non-viscous damping (Cundall 1987): each nodal force component is reduced by
// alpha |f| in the direction opposing the nodal velocity, f <- f - alpha |f| sign(v).
// Used to reach static states (gravity initialisation); it does not damp rigid-body motion.
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class LocalDamping : public Damping<D> {
 public:
  static constexpr const char* name = "local";
  static constexpr const char* summary =
      "Cundall local damping: f -= alpha |f| sign(v) at each node";
  static Schema schema() {
    Schema s;
    s.real("alpha", "-", "damping coefficient (0: none; 0.1-0.8 typical)")
        .required()
        .min(0)
        .below(1);
    s.boolean("liquid",
              "also damp the liquid's momentum balance (two-phase schemes): a settle stage that "
              "brings water to rest, e.g. at a free surface a B-spline grid integrates "
              "inexactly (docs/verification.md F); leave it off where water should flow, it "
              "slows seepage")
        .def("false");
    return s;
  }
  explicit LocalDamping(const Params& p)
      : alpha_(p.real("alpha")),
        phases_(p.flag("liquid") ? DampedPhases::solid_and_liquid : DampedPhases::solid) {}
  DampedPhases phases() const override { return phases_; }
  /// Per node, on the stored box (docs/parallel.md).
  bool runs_on_ranks() const override { return true; }
  void apply(Simulation<D>& sim, const NodeForces& nf) override {
    const long n = long(nf.num_nodes);
    const double tol = sim.mass_tolerance;
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long i = 0; i < n; ++i) {
      if (nf.mass[size_t(i) * size_t(nf.stride)] <= tol) continue;
      for (int d = 0; d < D; ++d) {
        double& f = nf.force.at(size_t(i), d);
        const double v = nf.momentum.at(size_t(i), d);
        if (v != 0.0) f -= alpha_ * std::fabs(f) * (v > 0 ? 1.0 : -1.0);
      }
    }
  }

 private:
  double alpha_;
  DampedPhases phases_;
};

LOAM_REGISTER(Damping, LocalDamping)

}  // namespace loam
