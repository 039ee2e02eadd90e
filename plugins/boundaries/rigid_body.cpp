// A rigid body with a prescribed motion: the particles of a body (`body`) impose the body's
// velocity v f(t) (f its time function of the loads' time, absent: 1), or the velocity
// u (f(t + dt) - f(t)) / dt that moves it by the displacement u f(t) (a table of f gives a
// displacement history: each step ends on it), on every grid node they
// touch, in the components `directions` (default: all, a rough contact bonded to the soil).
// Every node of such a particle's stencil then moves at v, so the particle moves at v and its
// velocity gradient sum_I v grad N_I is zero (partition of unity): the body translates without
// strain, as one piece. With some directions only (e.g. [y], a footing smooth along x) the free
// components follow the grid like any particle's: the body is rigid only in the imposed ones
// and strains in the others (its material then acts). Unlike a prescribed_velocity box, whose
// nodes stay where they are in space, the held nodes follow the body: a footing stays in contact
// with the soil it pushes down, a pile or a cone goes on into the ground, a wall translates.
// The nodes are found each step when the forces are gathered (add_forces: before damping and
// the boundary passes), from the body's particles at x^n and the shape function's stencil. Its
// reaction (framework/reactions.hpp; `name`, default rigid_body_<position>) is the force on the
// soil, the body's weight under gravity and its inertia m dv/dt (zero at a constant velocity);
// a probe on one of its particles (particle_near, fields [displacement]) gives its displacement.
// Limits of this bonded form: translation only; no separation, no Coulomb sliding between the
// body and the soil. Under mpirun the nodes each rank finds are shared over the ranks, so every
// copy of a node the body reaches is held.
//
// A body listed under `contact:` moves instead on its own velocity field as one piece
// (framework/rigid_motion.hpp, framework/contact_fields.hpp): the contact law acts between it
// and the other bodies (friction, separation), it translates and rotates, and the components
// `directions` (default all for `motion: prescribed`, none for `motion: free`) follow the
// prescribed velocity while the others (and the rotation, unless `rotation: fixed`) follow the
// forces on it: gravity, its particle loads, the other bodies' contact, and the faces that hold
// the nodes it reaches. Its reaction is then the force its prescribed components and those faces
// apply to it. Either way the body's material is not used but in the time step (its wave speed
// counts: give the soil's stiffness, not steel's).
#include <algorithm>

#include "framework/load_time.hpp"
#include "framework/registry.hpp"
#include "framework/rigid_motion.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class RigidBody : public Boundary<D>, public RigidMotion<D> {
 public:
  static constexpr const char* name = "rigid_body";
  static constexpr const char* summary =
      "a body's particles impose a prescribed velocity on the nodes they touch: a rigid "
      "footing, pile or wall that moves with its particles";
  static Schema schema() {
    Schema s;
    add_reaction_name(s);
    s.text("body", "the body that moves rigidly (its particles)").required();
    s.choice("motion", {"prescribed", "free"},
             "prescribed: the body moves at `velocity` in `directions`; free (a body under "
             "contact only): it follows the forces on it but in `directions`. Under contact "
             "the body moves as one piece in every component either way (docs/contact.md); "
             "the faces that hold it are fixed and slip faces (not friction faces or "
             "prescribed_velocity boxes); two rigid bodies pass through each other")
        .def("prescribed");
    s.vector("velocity", "m/s",
             "the body's velocity v f(t) (components in `directions`); this or `displacement` "
             "unless the motion is free in every component");
    s.vector("displacement", "m",
             "instead of a velocity: the body moves by the displacement u f(t) (components in "
             "`directions`; give the time_function, e.g. a table of (time, factor) points)");
    s.string_list("directions",
                  "components prescribed (x, y, z); default all for a prescribed motion (bonded "
                  "contact when the body is not under contact), none for a free one");
    s.choice("rotation", {"free", "fixed"},
             "a body under contact: whether it rotates with the moments on it or keeps its "
             "orientation")
        .def("free");
    s.plugin("time_function", "time_function",
             "factor f(t) on the velocity, or on the displacement, over the loads' time (absent: "
             "1)");
    add_phase_param(s);
    return s;
  }
  explicit RigidBody(const Params& p)
      : params_(p),
        body_name_(p.text("body")),
        phases_(parse_phase_mask(p)),
        f_(p),
        free_(p.text("motion") == "free"),
        fixed_rotation_(p.text("rotation") == "fixed"),
        by_displacement_(p.has("displacement")) {
    const char* key = by_displacement_ ? "displacement" : "velocity";
    if (p.has(key))
      for (int d = 0; d < D; ++d) v_[size_t(d)] = p.vec(key)[size_t(d)];
  }
  bool applies_to(int phase) const override { return (phases_ >> phase) & 1; }
  bool runs_on_ranks() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    check_phase_mask(phases_, sim.scheme->phases(), params_, diag);
    if (!params_.has("directions")) {
      if (!free_)
        for (int d = 0; d < D; ++d) dirs_.push_back(d);
    } else {
      for (const auto& name : params_.strings("directions")) {
        const auto at = std::string("xyz").find(name);
        if (name.size() != 1 || at == std::string::npos || int(at) >= D)
          diag.error(params_.where("directions"), params_.path("directions"),
                     "unknown direction '" + name + "' (x, y" + (D == 3 ? ", z" : "") + ")");
        else
          dirs_.push_back(int(at));
      }
    }
    body_ = sim.body_index(body_name_);
    if (body_ < 0)
      return sim.unknown_body(diag, params_.where("body"), params_.path("body"), body_name_);
    set_ = sim.body_set(body_);
    sim_ = &sim;
    check_motion(sim, diag);
    stencil_.allocate(sim.shape->max_nodes_per_particle());
    touched_.assign(sim.grid.num_nodes, 0);
  }

  /// The nodes the body's particles touch this step (their stencils' nodes with a weight).
  void add_forces(const GridForces&) const override {
    if (!in_contact_) refresh();
  }

  void constrain_grid_update(const GridUpdate& u) const override {
    if (in_contact_) return;
    refresh();
    impose_velocity<D>(u, nodes_, dirs_, now_, [&](int k) { return applies_to(k); });
  }
  /// The MUSL re-mapped velocities, and USF's velocities before the grid update (the first
  /// call of a step finds the step's nodes).
  void constrain(const NodalVector& v) const override {
    if (in_contact_) return;
    refresh();
    set_components<D>(v, nodes_, dirs_, now_);
  }
  void mark_held(HeldComponents& held) const override {
    if (!in_contact_) hold_components(held, nodes_, dirs_);
  }
  /// Under contact: no nodes (the contact fields report the force on the body).
  const std::vector<size_t>* reaction_nodes() const override { return &nodes_; }
  bool reaction_nodes_move() const override { return true; }

  const RigidMotion<D>* rigid_motion() const override { return in_contact_ ? this : nullptr; }
  int rigid_body() const override { return body_; }
  unsigned prescribed(double t, double dt, typename RigidDofs<D>::Vector& value) const override {
    value.setZero();
    unsigned mask = 0;
    const double f = factor(t, dt);
    for (int d : dirs_) {
      mask |= 1u << d;
      value(d) = v_[size_t(d)] * f;
    }
    if (fixed_rotation_)
      for (int k = D; k < RigidDofs<D>::Q; ++k) mask |= 1u << k;
    return mask;
  }

 private:
  /// Under contact (its body listed, or every body) the body moves on its own field; a free
  /// motion needs that, a velocity needs prescribed components, and these need a velocity.
  void check_motion(const Simulation<D>& sim, Diagnostics& diag) {
    if (sim.contact) {
      const auto& listed = sim.contact->bodies();
      in_contact_ =
          listed.empty() || std::find(listed.begin(), listed.end(), body_name_) != listed.end();
    }
    // Two in one list (a stage's list is set up beside the run's, which it replaces):
    // the one set up later sees the earlier.
    bool listed = false;
    for (const auto& b : sim.boundaries) listed = listed || b.get() == this;
    for (const auto& other : sim.boundaries)
      if (listed && in_contact_ && other.get() != this && other->rigid_motion() &&
          other->rigid_motion()->rigid_body() == body_)
        diag.error(params_.where("body"), params_.path("body"),
                   "another rigid_body of this list moves '" + body_name_ +
                       "': give one condition per body");
    if (free_ && !in_contact_)
      diag.error(params_.where("motion"), params_.path("motion"),
                 "a free rigid body moves on its own velocity field: list '" + body_name_ +
                     "' under contact.bodies (or give contact: without bodies)");
    const char* key = by_displacement_ ? "displacement" : "velocity";
    if (by_displacement_ && params_.has("velocity"))
      diag.error(params_.where("displacement"), params_.path("displacement"),
                 "give a velocity or a displacement, not both");
    if (by_displacement_ && !f_.present())
      diag.error(params_.where("displacement"), params_.path("displacement"),
                 "a displacement u f(t) needs the time_function f (with f = 1 the body would not "
                 "move)");
    if (!dirs_.empty() && !params_.has(key))
      diag.error(params_.where(), params_.path("velocity"),
                 "the prescribed components need a velocity (or a displacement)");
    if (dirs_.empty() && params_.has(key))
      diag.error(params_.where(key), params_.path(key),
                 std::string("a ") + key +
                     " for a free motion: name the components it prescribes in `directions`");
    if (params_.given("rotation") && !in_contact_)
      diag.error(params_.where("rotation"), params_.path("rotation"),
                 "rotation applies to a body under contact (this one is bonded to the grid "
                 "and only translates)");
  }
  /// The step's nodes and velocity, once per step (whichever call of the step comes first).
  void refresh() const {
    if (refreshed_ == sim_->step) return;
    refreshed_ = sim_->step;
    const double f = factor(sim_->time - sim_->loads_start, sim_->dt);
    for (int d = 0; d < D; ++d) now_[size_t(d)] = v_[size_t(d)] * f;
    find_nodes();
  }
  /// The factor on v_ over the step [t, t + dt]: f(t) on a velocity, the displacement's rate
  /// (f(t + dt) - f(t)) / dt.
  double factor(double t, double dt) const {
    if (!by_displacement_) return f_.value(t);
    return dt > 0 ? (f_.value(t + dt) - f_.value(t)) / dt : 0.0;
  }
  /// Blocks of the body's set that hold a particle of the body are evaluated (the set is sorted
  /// by cell, so the body's particles fill few blocks); every node with a weight is kept once.
  void find_nodes() const {
    for (size_t n : nodes_) touched_[n] = 0;
    nodes_.clear();
    const Particles<D>& P = sim_->sets[size_t(set_)].particles;
    for (size_t b = 0; b < P.size(); b += kBlock) {
      const int count = int(std::min<size_t>(kBlock, P.size() - b));
      bool mine = false;
      for (int p = 0; p < count && !mine; ++p) mine = P.body[b + size_t(p)] == body_;
      if (!mine) continue;
      sim_->shape->evaluate(sim_->grid, P, b, count, stencil_);
      for (int p = 0; p < count; ++p) {
        if (P.body[b + size_t(p)] != body_) continue;
        for (int k = 0; k < stencil_.npp; ++k) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          const size_t n = size_t(stencil_.node[kp]);
          if (stencil_.w[kp] > 0 && !touched_[n]) touched_[n] = 1, nodes_.push_back(n);
        }
      }
    }
    if (sim_->ranks->distributed()) share_nodes();
  }
  /// Under mpirun a node the body reaches from another rank's block is held here too (the
  /// flags completed over the ranks), so that every copy of a node is held alike.
  void share_nodes() const {
    flags_.assign(sim_->grid.num_nodes, 0.0);
    for (size_t n : nodes_) flags_[n] = 1;
    sim_->ranks->complete_nodes({{flags_.data(), 1, 1}});
    for (size_t n : nodes_) touched_[n] = 0;
    nodes_.clear();
    for (size_t n = 0; n < flags_.size(); ++n)
      if (flags_[n] > 0) touched_[n] = 1, nodes_.push_back(n);
  }

  Params params_;
  std::string body_name_;
  int phases_;
  TimeFactor<D> f_;
  std::array<double, D> v_{};  // the velocity v, or the displacement u
  std::vector<int> dirs_;
  bool free_, fixed_rotation_;
  bool by_displacement_;     // v_ is a displacement u: the velocity is its rate
  bool in_contact_ = false;  // moves on its own field (framework/contact_fields.hpp)
  int body_ = -1, set_ = 0;
  const Simulation<D>* sim_ = nullptr;
  mutable StencilBlock<D> stencil_;
  mutable std::vector<uint8_t> touched_;
  mutable std::vector<size_t> nodes_;    // the nodes the body touches this step
  mutable std::vector<double> flags_;    // under mpirun: per node, whether a rank's body reaches it
  mutable std::array<double, D> now_{};  // velocity of the current step
  mutable long refreshed_ = -2;          // the step whose nodes and velocity these are
};

LOAM_REGISTER(Boundary, RigidBody)

}  // namespace loam
