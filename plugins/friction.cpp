// Coulomb friction on a grid face (a rough or frictional base). Contact is unilateral: a node
// moving into the face has its normal velocity removed, which is a normal impulse per unit mass
// |v_n|; the tangential velocity is then reduced by at most mu |v_n| (Coulomb's law applied to
// the impulses of one step, as in the grid contact of Bardenhagen et al. 2000). A node moving
// away from the face is free. The acceleration is made consistent with the imposed velocity,
// a += (v_after - v_before) / dt, so that FLIP particle updates feel the friction as well.
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Friction : public Boundary<D> {
 public:
  static constexpr const char* name = "friction";
  static constexpr const char* summary =
      "Coulomb-frictional grid face (unilateral contact; mu = 0: free slip, large mu: no slip)";
  static Schema schema() {
    Schema s;
    s.choice("face", face_names(), "grid face").required();
    s.real("coefficient", "-", "Coulomb friction coefficient mu = tan(interface friction angle)")
        .required()
        .non_negative();
    return s;
  }
  explicit Friction(const Params& p)
      : params_(p), face_(parse_face(p.text("face"))), mu_(p.real("coefficient")) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(face_, D, params_, "face", diag)) return;
    nodes_ = face_nodes(sim.grid, face_);
  }

  /// Alone (a momentum or remapped velocity): unilateral contact without friction.
  void constrain(const NodalVector& v) const override {
    const int a = face_.axis;
    for (size_t n : nodes_)
      if (into_face(v.at(n, a))) v.at(n, a) = 0.0;
  }

  void constrain_update(const NodalVector& v, const NodalVector& acc, double dt) const override {
    const int a = face_.axis;
    for (size_t n : nodes_) {
      const double vn = v.at(n, a);
      if (!into_face(vn)) continue;
      double vt2 = 0;
      for (int d = 0; d < D; ++d)
        if (d != a) vt2 += v.at(n, d) * v.at(n, d);
      const double vt = std::sqrt(vt2);
      // Tangential speed left after the friction impulse mu |v_n| (never reversed).
      const double scale = vt > 0 ? std::max(0.0, vt - mu_ * std::fabs(vn)) / vt : 0.0;
      for (int d = 0; d < D; ++d) {
        const double before = v.at(n, d);
        const double after = d == a ? 0.0 : before * scale;
        v.at(n, d) = after;
        if (dt > 0) acc.at(n, d) += (after - before) / dt;
      }
    }
  }

 private:
  bool into_face(double vn) const { return face_.upper ? vn > 0 : vn < 0; }

  Params params_;
  Face face_;
  double mu_;
  std::vector<size_t> nodes_;
};

LOAM_REGISTER(Boundary, Friction)

}  // namespace loam
