#pragma once
// Boundary-condition plugin interface: constrains nodal velocity (and acceleration) components.
// Schemes call Simulation::constrain() on every nodal vector that must respect the constraints,
// and Simulation::constrain_update() once on the grid update of a step (all phases, with nodal
// masses), which runs the conditions in passes whatever the order of the config: records
// (before_constraints), the kinematic pass (constrain_grid_update, marking HeldComponents), the
// Coulomb pass (coulomb_update) and the hydraulic conditions. A mechanical condition that
// holds the normal motion of its face says so (holds_face): no particle crosses that face
// (HeldFaces, applied by the schemes wherever they move particles).
#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "force_inline.hpp"
#include "grid.hpp"

namespace loam {

template <int D>
class Simulation;
template <int D>
class RigidMotion;
class Diagnostics;
class Params;

/// One phase of a grid update: the updated nodal velocity v^{n+1}, the acceleration a with
/// v^{n+1} = v^n + dt a, and the phase's lumped nodal mass mass.at(n, 0) (kg; per unit area in
/// 1D and per unit thickness in 2D, like the particle masses). Nodes with no mass have zero
/// velocity and acceleration.
struct PhaseUpdate {
  NodalVector velocity, acceleration, mass;
};

/// Per grid node, the velocity components of one phase that the mechanical conditions hold in
/// the current grid update (bit d: component d). A node held by several faces (an edge or a
/// corner) gets every normal/kinematic constraint first; Coulomb friction then acts only in the
/// components left free (Bardenhagen et al. 2000), so the result does not depend on the order
/// the faces are listed in. The Simulation owns one per phase and clears it before each update,
/// on the nodes marked by the previous one only (face nodes, not the whole grid).
class HeldComponents {
 public:
  void hold(size_t node, int d) {
    uint8_t& b = bits_[node];
    if (!b) marked_.push_back(node);
    b = uint8_t(b | (1u << d));
  }
  bool held(size_t node, int d) const {
    return node < bits_.size() && ((bits_[node] >> d) & 1u);  // none before the first update
  }
  /// Nothing held, on a grid of num_nodes nodes.
  void clear(size_t num_nodes) {
    if (bits_.size() != num_nodes) {
      bits_.assign(num_nodes, 0);
    } else {
      for (size_t n : marked_) bits_[n] = 0;
    }
    marked_.clear();
  }

 private:
  std::vector<uint8_t> bits_;
  std::vector<size_t> marked_;  // nodes with a bit set
};

/// The grid update of one step, after the scheme's own implicit terms (e.g. drag). phases[0] is
/// the scheme's only phase or the solid skeleton; phases[1], when count == 2, is the pore water
/// of a two-phase scheme (its velocity is the water's own, not relative to the skeleton).
struct GridUpdate {
  std::array<PhaseUpdate, 2> phases;
  int count = 1;
  double dt = 0;
  /// Two-phase: the nodal porosity porosity.at(n, 0) (volume-weighted from the particles).
  NodalVector porosity{nullptr, 0, 0};
  /// The components held per phase, set by Simulation::constrain_update (schemes leave them
  /// null; a condition driven alone, e.g. by a unit test, must accept null).
  std::array<HeldComponents*, 2> held{};
  /// The loads' time (since the stage that set the running loads began), for time functions.
  double time = 0;
};

/// The nodal forces of a grid step before the scheme integrates them. mixture: the force of the
/// scheme's only phase, or the mixture (total) force of a two-phase scheme; water, when count ==
/// 2: the pore water's force (its momentum equation), with the nodal porosity. Conditions that
/// act by a force rather than a constraint (a prescribed pore pressure on a face) add it here, so
/// the scheme integrates it with the rest (implicitly in the drag of a two-phase scheme).
struct GridForces {
  NodalVector mixture{nullptr, 0, 0}, water{nullptr, 0, 0}, porosity{nullptr, 0, 0};
  int count = 1;
  /// Single-phase schemes: the nodal mass mass.at(n, 0) and momentum of the step, which a
  /// condition may change together with the force (periodic joins node pairs); else null.
  NodalVector mass{nullptr, 0, 0}, momentum{nullptr, 0, 0};
  /// The loads' time (since the stage that set the running loads began), for time functions.
  double time = 0;
};

template <int D>
class Boundary {
 public:
  static constexpr const char* kind = "boundary";
  virtual ~Boundary() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): it reads and writes only
  /// the particles of this rank and the stored box of nodes, each node as the whole grid's
  /// value. Default false: a run under mpirun refuses it with a located error.
  virtual bool runs_on_ranks() const { return false; }
  /// Add face forces to the nodal forces of a step, before the grid update (default: none).
  virtual void add_forces(const GridForces&) const {}
  /// Whether add_forces adds forces (rather than none, or joining nodes): their work then goes
  /// to the energy balance (framework/energy_ledger.hpp), which records the nodal forces around
  /// the call.
  virtual bool adds_forces() const { return false; }
  /// Checkpoints (output.checkpoint): a condition's state measured during the run (e.g. the
  /// reaction an absorbing face took over at its first step), appended as doubles and restored
  /// bit for bit on --resume. false (default): it has none.
  virtual bool save_state(std::vector<double>&) const { return false; }
  virtual void restore_state(const std::vector<double>&) {}
  /// Zero the constrained components of `v` (a velocity, momentum, acceleration or force). On
  /// the MUSL re-mapped velocities this is the only call (Simulation::constrain): holds only, no
  /// friction impulse, since the particles already carry the step's impulse from the update.
  virtual void constrain(const NodalVector& v) const = 0;
  /// Constrain the velocity v^{n+1} and acceleration a of one phase of a grid update together
  /// (v^{n+1} = v^n + dt a). Default: constrain() both.
  virtual void constrain_update(const NodalVector& v, const NodalVector& a, double /*dt*/) const {
    constrain(v);
    constrain(a);
  }
  /// Mark the components constrain() holds at this condition's nodes (fixed: all of them, slip:
  /// its directions), for the Coulomb pass. Default: none.
  virtual void mark_held(HeldComponents&) const {}
  /// Kinematic pass of the grid update: every phase at once, with the nodal masses. A
  /// condition that applies a force integrated implicitly (a dashpot: v^{n+1} = m v* / (m + dt
  /// C) needs m), couples the phases or holds a component only under a condition (unilateral
  /// contact) overrides this, marks what it holds in u.held, and keeps a consistent with the
  /// velocity it imposes, a += (v_after - v_before) / dt, so FLIP particles see it too. Default:
  /// constrain_update and mark_held for each phase it applies to.
  virtual void constrain_grid_update(const GridUpdate& u) const {
    for (int k = 0; k < u.count; ++k)
      if (applies_to(k)) {
        constrain_update(u.phases[size_t(k)].velocity, u.phases[size_t(k)].acceleration, u.dt);
        if (u.held[size_t(k)]) mark_held(*u.held[size_t(k)]);
      }
  }
  /// Coulomb pass, after the kinematic pass of every mechanical condition: a frictional
  /// condition reduces the velocity in the components no condition holds (u.held), with a
  /// budget taken from what it recorded before any constraint (before_constraints). Default:
  /// nothing.
  virtual void coulomb_update(const GridUpdate&) const {}
  /// Whether constrain() acts on phase k (0: the only phase or the solid, 1: the pore water).
  virtual bool applies_to(int /*phase*/) const { return true; }
  /// Hydraulic conditions (drained, impermeable, prescribed pore pressure) act on the water
  /// after every mechanical condition, whatever the order of the config.
  virtual bool hydraulic() const { return false; }
  /// Called on every condition before any condition acts on the grid update: record the
  /// unconstrained state the condition needs (the water's update to release it on a drained face, a
  /// friction face's normal velocity).
  virtual void before_constraints(const GridUpdate&) {}
  /// The same before the conditions act on a single nodal vector of `phase`.
  virtual void before_constrain(const NodalVector& /*v*/, int /*phase*/) {}
  /// The grid face (face_index) whose normal motion this condition holds for the particles of
  /// `phase` (0: the only phase or the solid, 1: the water), or -1 (default: none; hydraulic
  /// conditions and faces that leave the phase's normal free). The Simulation collects them at
  /// set-up (HeldFaces) and the schemes keep every particle on or inside a held face, whatever
  /// the interpolated grid velocity near it.
  virtual int holds_face(int /*phase*/) const { return -1; }
  /// The grid face on which this (hydraulic) condition lets the water through although a
  /// mechanical condition holds it there (drained, a prescribed pore pressure), or -1: the
  /// water's own points (a double-point scheme's liquid set) may leave through that face.
  virtual int releases_face() const { return -1; }
  /// The axis along which this condition makes the grid periodic (particles leaving through
  /// one face of it enter through the other: HeldFaces), or -1 (default).
  virtual int periodic_axis() const { return -1; }
  /// The nodes where this mechanical condition acts, for its reaction (framework/reactions.hpp:
  /// the force it applies there), after setup; nullptr (default): it reports none (hydraulic
  /// conditions, periodic faces).
  virtual const std::vector<size_t>* reaction_nodes() const { return nullptr; }
  /// Whether those nodes change from step to step (a rigid body's), so the reaction takes
  /// them anew each time. Default false.
  virtual bool reaction_nodes_move() const { return false; }
  /// A condition that makes a body in contact rigid (framework/rigid_motion.hpp): the contact
  /// fields move that body's field as one piece and report its reaction here. Default null.
  virtual const RigidMotion<D>* rigid_motion() const { return nullptr; }
};

/// Set components `dirs` of `nodes` to `velocity` in the phases of u that `applies(k)` selects,
/// at nodes with mass, keeping the acceleration consistent (a += (v - v*)/dt, so FLIP particles
/// see the motion) and marking the components held (prescribed_velocity, rigid_body).
template <int D, class Applies>
void impose_velocity(const GridUpdate& u, const std::vector<size_t>& nodes,
                     const std::vector<int>& dirs, const std::array<double, D>& velocity,
                     Applies&& applies) {
  for (int k = 0; k < u.count; ++k) {
    if (!applies(k)) continue;
    const PhaseUpdate& p = u.phases[size_t(k)];
    for (size_t n : nodes) {
      if (!(p.mass.at(n, 0) > 0)) continue;
      for (int d : dirs) {
        const double before = p.velocity.at(n, d);
        p.velocity.at(n, d) = velocity[size_t(d)];
        if (u.dt > 0) p.acceleration.at(n, d) += (velocity[size_t(d)] - before) / u.dt;
        if (u.held[size_t(k)]) u.held[size_t(k)]->hold(n, d);
      }
    }
  }
}

/// Components `dirs` of `nodes` set to `value` in a single nodal vector (the MUSL re-mapped
/// velocities), and marked held for the Coulomb pass (prescribed_velocity, rigid_body, slip).
template <int D>
void set_components(const NodalVector& v, const std::vector<size_t>& nodes,
                    const std::vector<int>& dirs, const std::array<double, D>& value) {
  for (size_t n : nodes)
    for (int d : dirs) v.at(n, d) = value[size_t(d)];
}
inline void hold_components(HeldComponents& held, const std::vector<size_t>& nodes,
                            const std::vector<int>& dirs) {
  for (size_t n : nodes)
    for (int d : dirs) held.hold(n, d);
}

/// The nodes on one face of the grid ("x-", "x+", "y-", ...), for face-based plugins.
struct Face {
  int axis = 0;
  bool upper = false;
};
Face parse_face(const std::string& name);
/// The face's position in face_names(): 2 axis + upper ("x-" 0, "x+" 1, "y-" 2, ...).
inline int face_index(const Face& f) {
  return 2 * f.axis + (f.upper ? 1 : 0);
}

/// The faces that hold the particles of one phase, as bounds per axis: lower[d] is the grid's
/// lower coordinate along d if some condition holds face 2 d for the phase
/// (Boundary::holds_face) and, for the water (phase 1), no condition releases it
/// (Boundary::releases_face), else -inf; upper[d] likewise. Schemes pass every particle move
/// through moved(). A particle leaving through an open face is left alone, for
/// Simulation::check_particles to report (exit 3) or a sink to remove.
template <int D>
struct HeldFaces {
  std::array<double, D> lower, upper;
  std::array<double, D> period{};  // > 0 along a periodic axis: the grid's length
  HeldFaces() {
    lower.fill(-std::numeric_limits<double>::infinity());
    upper.fill(std::numeric_limits<double>::infinity());
  }
  template <class Boundaries>
  HeldFaces(const Grid<D>& grid, const Boundaries& boundaries, int phase = 0) : HeldFaces() {
    for (const auto& b : boundaries) {
      const int a = b->periodic_axis();
      if (a >= 0 && a < D) {
        lower[size_t(a)] = grid.origin[size_t(a)];
        upper[size_t(a)] = grid.upper(a);
        period[size_t(a)] = upper[size_t(a)] - lower[size_t(a)];
      }
      const int f = b->holds_face(phase);
      if (f < 0 || f >= 2 * D) continue;
      bool released = false;
      for (const auto& r : boundaries)
        released = released || (phase == 1 && r->releases_face() == f);
      if (released) continue;
      const int d = f / 2;
      if (f % 2)
        upper[size_t(d)] = grid.upper(d);
      else
        lower[size_t(d)] = grid.origin[size_t(d)];
    }
  }
  /// Coordinate d of a particle at x after the move dx. A move that would reach or cross a held
  /// face stops halfway between x and the face instead. Not on the face: there every shape
  /// function weights the face nodes alone (the boundary half-cell is linear, S_1 = t = 0), so
  /// the normal velocity would stay the face's zero and a slip or fixed face would keep the
  /// particle for good (a water particle stopped on a slip lid was still on it 45 s later).
  /// Halfway follows the approach to a held face that the grid gives when it does not
  /// overshoot: the normal velocity t v_1 falls with the distance t h. Only the position
  /// changes, never the velocity, so no momentum is added. Comparisons keep a NaN a NaN, for
  /// Simulation::check_particles. Along a periodic axis a move beyond a face wraps by the
  /// grid's length instead (the faces are one: the particle stays in [lower, upper)).
  LOAM_FORCE_INLINE double moved(int d, double x, double dx) const {
    const double to = x + dx, lo = lower[size_t(d)], hi = upper[size_t(d)];
    if (to <= lo)
      return period[size_t(d)] ? (to < lo ? to + period[size_t(d)] : to) : lo + 0.5 * (x - lo);
    if (to >= hi) return period[size_t(d)] ? to - period[size_t(d)] : hi - 0.5 * (hi - x);
    return to;
  }
};
template <int D>
std::vector<size_t> face_nodes(const Grid<D>& grid, const Face& face);
/// Report a face that does not exist in this dimension; returns false then.
bool check_face(const Face& f, int dim, const Params& p, const std::string& key, Diagnostics& d);
/// Which phases of a two-phase scheme a mechanical face condition holds (YAML `phase`): both
/// (default: the face is also impermeable to the water), solid (the water passes: a drained
/// face) or water (the water is held, the skeleton free). Bit 0: solid, bit 1: water.
class Schema;
void add_phase_param(Schema& s);
int parse_phase_mask(const Params& p);
/// Report `phase: solid` or `water` under a scheme without a water phase; returns false then.
bool check_phase_mask(int mask, int scheme_phases, const Params& p, Diagnostics& d);
/// Tributary face area of each node of face_nodes(grid, face) (m^(D-1); 1 in 1D, where masses
/// are per unit area): the cell sizes along the face, halved at the grid's edges.
template <int D>
std::vector<double> face_node_areas(const Grid<D>& grid, const Face& face,
                                    const std::vector<size_t>& nodes);
const std::vector<std::string>& face_names();

/// The optional `name` of a mechanical condition: its reaction's columns in history.csv and
/// its entry in summary.json (framework/reactions.hpp).
void add_reaction_name(Schema& s);

/// A condition on a box of nodes inside the grid instead of a face (fixed, slip: a sheet pile,
/// a wall, a footing): the schema keys `min` and `max` beside `face`, exactly one of the two
/// ways checked (a box may be flat, one row of nodes, not inverted).
void add_face_or_box_params(Schema& s, bool face_required_otherwise);
/// The nodes inside [min, max] of p (to 1e-9 of a cell); a located error if there is none.
template <int D>
std::vector<size_t> box_nodes(const Grid<D>& grid, const Params& p, Diagnostics& d);

/// The nodes of a face-or-box condition (a box: box_nodes; a face: face_nodes, after
/// check_face) and the components it acts on: those named in `directions` (x, y, z), or the
/// face normal without it. Unknown names are located errors. (slip, prescribed_velocity)
template <int D>
void face_or_box_components(const Grid<D>& grid, const Params& p, const Face& face, bool box,
                            std::vector<size_t>& nodes, std::vector<int>& components,
                            Diagnostics& d);

}  // namespace loam
