// Impermeable face of a two-phase scheme: no water crosses it relative to the skeleton, so both
// phases share the normal velocity there, w_n = v_n = (m_s v_s + m_w w) / (m_s + m_w) (normal
// momentum conserved); the tangential water velocity is free. It is for a face where the
// skeleton moves (a sealed, loaded top): where it is held, fixed or slip with their default
// `phase: both` are already impermeable (this condition would move a held skeleton). Both the grid
// update and the MUSL re-mapped velocities (whose gradients drive the storage equation) are tied.
#include "framework/hydraulic_face.hpp"
#include "framework/registry.hpp"

namespace loam {

template <int D>
class Impermeable : public HydraulicFace<D> {
 public:
  static constexpr const char* name = "impermeable";
  static constexpr const char* summary =
      "two-phase: no water flow through the grid face relative to the skeleton (w_n = v_n)";
  static Schema schema() {
    Schema s;
    HydraulicFace<D>::add_face(s);
    return s;
  }
  explicit Impermeable(const Params& p) : HydraulicFace<D>(p) {}
  const char* condition() const override { return name; }
  /// Per node of the face, on the stored box (docs/parallel.md).
  bool runs_on_ranks() const override { return true; }
  /// Also called for the solid (phase 0), to read its constrained velocity on the face.
  bool applies_to(int) const override { return true; }
  /// MUSL re-mapped velocities come one phase at a time, solid first: keep the solid's normal
  /// component, then give it to the water.
  void before_constrain(const NodalVector&, int phase) override { phase_ = phase; }
  void constrain(const NodalVector& v) const override {
    const int a = this->face_.axis;
    if (phase_ == 0) {
      solid_.resize(this->nodes_.size());
      for (size_t k = 0; k < this->nodes_.size(); ++k) solid_[k] = v.at(this->nodes_[k], a);
    } else if (solid_.size() == this->nodes_.size()) {
      for (size_t k = 0; k < this->nodes_.size(); ++k) v.at(this->nodes_[k], a) = solid_[k];
    }
  }
  void constrain_grid_update(const GridUpdate& u) const override {
    if (u.count < 2 || !(u.dt > 0)) return;
    const int a = this->face_.axis;
    for (size_t n : this->nodes_) {
      const double ms = u.phases[0].mass.at(n, 0), mw = u.phases[1].mass.at(n, 0);
      if (!(mw > 0) || !(ms > 0)) continue;
      // Common normal velocity with the normal momentum of the node conserved: the seal
      // passes the water's push on it to the skeleton (tying only the water would delete it).
      const double vs = u.phases[0].velocity.at(n, a), vw = u.phases[1].velocity.at(n, a);
      const double vn = (ms * vs + mw * vw) / (ms + mw);
      u.phases[0].velocity.at(n, a) = vn;
      u.phases[0].acceleration.at(n, a) += (vn - vs) / u.dt;
      u.phases[1].velocity.at(n, a) = vn;
      u.phases[1].acceleration.at(n, a) += (vn - vw) / u.dt;
    }
  }

 private:
  int phase_ = 0;                      // phase of the nodal vector being constrained
  mutable std::vector<double> solid_;  // the solid's re-mapped normal velocity on the face
};

LOAM_REGISTER(Boundary, Impermeable)

}  // namespace loam
