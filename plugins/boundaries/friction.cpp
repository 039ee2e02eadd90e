// Coulomb friction on a grid face (a rough or frictional base). Contact is unilateral: a node
// moving into the face has its normal velocity removed, which is a normal impulse per unit mass
// |v_n|; the tangential velocity is then reduced by at most mu |v_n| (Coulomb's law applied to
// the impulses of one step, as in the grid contact of Bardenhagen, Brackbill & Sulsky 2000,
// CMAME 187: the normal correction first, then the frictional one, bounded by mu times it).
// A node moving away from the face is free. The acceleration is made consistent with the
// imposed velocity, a += (v_after - v_before) / dt, so that FLIP particle updates feel the
// friction as well.
//
// Edges and corners, where this face meets other conditions (Simulation::constrain_update):
// the budget mu |v_n| and the contact test use v_n as it was before any condition acted
// (before_constraints), the normal is removed in the kinematic pass with every other hold
// (slip, fixed, another friction face's normal), and the Coulomb impulse acts in the Coulomb
// pass only on the components that no condition holds at the node. So at the edge of this
// base and a slip wall the wall's normal is not part of the sliding velocity, and two friction
// faces at an edge reduce the same free tangential speed, |v_t| -> max(0, |v_t| - mu_1 |v_n1|
// - mu_2 |v_n2|): nothing depends on the order the faces are listed in.
//
// Two-phase schemes: the face acts on both phases alike (it has no `phase` option). On the
// MUSL re-mapped velocities (constrain) it is only the unilateral contact: the particles already
// carry this step's friction impulse from the grid update, which would otherwise be applied twice.
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Friction : public Boundary<D> {
 public:
  static constexpr const char* name = "friction";
  static constexpr const char* summary =
      "Coulomb-frictional grid face (unilateral contact; mu = 0: free slip, large mu: no slip; "
      "at edges it slides only in the components other faces leave free)";
  static Schema schema() {
    Schema s;
    add_reaction_name(s);
    s.choice("face", face_names(), "grid face").required();
    s.real("coefficient", "-",
           "Coulomb friction coefficient mu = tan(interface friction angle); per step the "
           "tangential speed drops by at most mu |v_n|, v_n the normal velocity into the face "
           "before any condition acts")
        .required()
        .non_negative();
    return s;
  }
  explicit Friction(const Params& p)
      : params_(p), face_(parse_face(p.text("face"))), mu_(p.real("coefficient")) {}

  /// Per node, on the stored box (docs/parallel.md).
  bool runs_on_ranks() const override { return true; }
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

  /// Contact is unilateral: the particles may move away from the face, never through it.
  int holds_face(int) const override { return face_index(face_); }

  /// The normal velocity of every phase on the face before any condition acts: it decides the
  /// contact and sets the budget mu |v_n| even where a slip or fixed face holds v_n as well.
  void before_constraints(const GridUpdate& u) override {
    const int a = face_.axis;
    normal_.resize(size_t(u.count) * nodes_.size());
    for (int k = 0; k < u.count; ++k)
      for (size_t i = 0; i < nodes_.size(); ++i)
        normal_[size_t(k) * nodes_.size() + i] = u.phases[size_t(k)].velocity.at(nodes_[i], a);
  }

  /// Kinematic pass: remove the normal velocity of the nodes in contact and mark it held.
  void constrain_grid_update(const GridUpdate& u) const override {
    const int a = face_.axis;
    for (int k = 0; k < u.count; ++k) {
      const PhaseUpdate& ph = u.phases[size_t(k)];
      for (size_t i = 0; i < nodes_.size(); ++i) {
        const size_t n = nodes_[i];
        if (!into_face(normal_before(u, k, i))) continue;
        set(ph, n, a, 0.0, u.dt);
        if (u.held[size_t(k)]) u.held[size_t(k)]->hold(n, a);
      }
    }
  }

  /// Coulomb pass: the tangential velocity in the components no condition holds drops by at
  /// most mu |v_n| (never reversed).
  void coulomb_update(const GridUpdate& u) const override {
    const int a = face_.axis;
    for (int k = 0; k < u.count; ++k) {
      const PhaseUpdate& ph = u.phases[size_t(k)];
      const HeldComponents* held = u.held[size_t(k)];
      for (size_t i = 0; i < nodes_.size(); ++i) {
        const size_t n = nodes_[i];
        const double vn = normal_before(u, k, i);
        if (!into_face(vn)) continue;
        bool free[D];
        double vt2 = 0;
        for (int d = 0; d < D; ++d) {
          free[d] = d != a && !(held && held->held(n, d));
          if (free[d]) vt2 += ph.velocity.at(n, d) * ph.velocity.at(n, d);
        }
        const double vt = std::sqrt(vt2);
        if (!(vt > 0)) continue;
        const double scale = std::max(0.0, vt - mu_ * std::fabs(vn)) / vt;
        for (int d = 0; d < D; ++d)
          if (free[d]) set(ph, n, d, scale * ph.velocity.at(n, d), u.dt);
      }
    }
  }

  const std::vector<size_t>* reaction_nodes() const override { return &nodes_; }

 private:
  bool into_face(double vn) const { return face_.upper ? vn > 0 : vn < 0; }
  /// v_n of node i of phase k as recorded before the constraints. Simulation::constrain_update
  /// (which sets u.held) always records first; a condition driven alone uses the current v_n.
  double normal_before(const GridUpdate& u, int k, size_t i) const {
    if (!u.held[size_t(k)] || normal_.size() != size_t(u.count) * nodes_.size())
      return u.phases[size_t(k)].velocity.at(nodes_[i], face_.axis);
    return normal_[size_t(k) * nodes_.size() + i];
  }
  /// v <- after for component d of node n, with a consistent acceleration.
  static void set(const PhaseUpdate& ph, size_t n, int d, double after, double dt) {
    const double before = ph.velocity.at(n, d);
    ph.velocity.at(n, d) = after;
    if (dt > 0) ph.acceleration.at(n, d) += (after - before) / dt;
  }

  Params params_;
  Face face_;
  double mu_;
  std::vector<size_t> nodes_;
  std::vector<double> normal_;  // [phase][face node]: v_n before the constraints of the update
};

LOAM_REGISTER(Boundary, Friction)

}  // namespace loam
