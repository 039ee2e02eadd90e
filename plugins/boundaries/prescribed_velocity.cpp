// Prescribed velocity on a grid face or on a box of nodes: a moving platen, a displacement-
// controlled test (a biaxial specimen compressed at a constant rate), a wave maker. The nodes'
// components in `directions` (default: the face normal) move at velocity_d f(t), f its time
// function of the loads' time (absent: 1); the other components are free. In the grid update
// the velocity is set and the acceleration kept consistent with it, a += (v - v*)/dt, so FLIP
// particles see the motion too; the held components are marked, so friction on a face meeting
// this one acts only in the others. The MUSL re-mapped velocities get the same values. Only
// nodes with mass move (the scheme leaves empty nodes at rest). The grid does not move: a face
// carries the particles next to it while they stay within its nodes' reach (under a cell of
// travel with linear shape functions); for longer strokes prescribe a box of nodes as deep as the
// stroke (the platen's band), which moves whatever particles are inside it.
#include <algorithm>
#include <memory>

#include "framework/load_time.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class PrescribedVelocity : public Boundary<D> {
 public:
  static constexpr const char* name = "prescribed_velocity";
  static constexpr const char* summary =
      "grid face or box of nodes moving at a prescribed velocity (platens, displacement control)";
  static Schema schema() {
    Schema s;
    add_reaction_name(s);
    add_face_or_box_params(s, /*face_required_otherwise=*/true);
    add_phase_param(s);
    s.vector("velocity", "m/s", "the velocity (only the components in `directions` are used)")
        .required();
    s.string_list("directions",
                  "components to prescribe (x, y, z); default: the face normal (required with a "
                  "box)");
    s.plugin("time_function", "time_function",
             "factor f(t) on the velocity over the loads' time (absent: 1)");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.has("min") && !p.has("directions"))
        d.error(p.where(), p.path(), "a box has no normal: give directions (e.g. [y])");
    });
    return s;
  }
  explicit PrescribedVelocity(const Params& p)
      : params_(p),
        face_(parse_face(p.has("face") ? p.text("face") : "x-")),
        box_(!p.has("face")),
        phases_(parse_phase_mask(p)),
        f_(p) {
    for (int d = 0; d < D; ++d) v_[size_t(d)] = p.vec("velocity")[size_t(d)];
  }
  bool applies_to(int phase) const override { return (phases_ >> phase) & 1; }
  /// Per node of the stored box (docs/parallel.md), on a face or a box of nodes.
  bool runs_on_ranks() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    check_phase_mask(phases_, sim.scheme->phases(), params_, diag);
    face_or_box_components(sim.grid, params_, face_, box_, nodes_, dirs_, diag);
  }

  /// The velocity of this step (kept for the MUSL re-map of the same step).
  void constrain_grid_update(const GridUpdate& u) const override {
    const double f = f_.value(u.time);
    for (int d = 0; d < D; ++d) now_[size_t(d)] = v_[size_t(d)] * f;
    impose_velocity<D>(u, nodes_, dirs_, now_, [&](int k) { return applies_to(k); });
  }
  /// The MUSL re-mapped velocities (the only other vectors the schemes constrain).
  void constrain(const NodalVector& v) const override { set_components<D>(v, nodes_, dirs_, now_); }
  void mark_held(HeldComponents& held) const override { hold_components(held, nodes_, dirs_); }

  const std::vector<size_t>* reaction_nodes() const override { return &nodes_; }

 private:
  Params params_;
  Face face_;
  bool box_;
  int phases_;
  std::array<double, D> v_{};
  TimeFactor<D> f_;
  std::vector<size_t> nodes_;
  std::vector<int> dirs_;
  mutable std::array<double, D> now_{};  // velocity of the current step
};

LOAM_REGISTER(Boundary, PrescribedVelocity)

}  // namespace loam
