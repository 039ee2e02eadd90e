// Viscous absorbing grid face (Lysmer & Kuhlemeyer 1969): dashpots on the nodes of one face so
// that waves leave the grid instead of reflecting, as if the material continued beyond the face.
// Per unit face area the face applies the tractions
//     t_n = -rho c_p v_n   (normal),        t_t = -rho c_s v_t   (tangential),
// with rho, c_p, c_s the density and P- and S-wave speeds of the material next to the face (given
// explicitly: this plugin reads nothing from the materials). For a plane wave at normal incidence
// this is exact: the impedance rho c_p of the material is matched and nothing is reflected.
//
// Per node the dashpot coefficient is C = rho c A, A the node's tributary area of the face: the
// product of the cell sizes along the face's other axes, halved for each axis along which the node
// lies on the grid's edge (1D: A = 1, since masses are per unit area; 2D: A = h or h/2 per unit
// thickness, since masses are per unit thickness; 3D: h1 h2, h1 h2 / 2 or h1 h2 / 4).
//
// The dashpot is integrated implicitly, so it is stable for any C: with m the lumped nodal mass and
// v* the velocity the scheme's update gave without the dashpot, m v^{n+1} = m v* - dt C v^{n+1},
//     v^{n+1} = m v* / (m + dt C)
// per damped component, and the acceleration is kept consistent with it, a += (v^{n+1} - v*)/dt,
// so that FLIP particle updates see the dashpot too. The face is otherwise free. A dashpot cannot
// carry a static load: a body pressed onto the face drifts at v = t / (rho c_p). Where it meets
// other faces it acts in the kinematic pass of Simulation::constrain_update and holds no
// component (with one phase its scaling commutes with the holds): a friction face sharing a
// node slides afterwards in the damped free components, its budget mu |v_n| taken before the
// dashpot.
//
// Two-phase schemes (solid and pore water, e.g. two_phase_single_point): the face is an
// IMPERMEABLE dashpot, as the viscous bottom (an impervious base with extra damping) of the
// consolidation column of "The Material Point Method: A promising computational tool in
// Geotechnics" (seed 002): water does not cross the face relative to the skeleton, so the normal
// velocities of solid and water at a face node are equal, and the mixture's normal dashpot acts on
// that common velocity with the mixture's momentum,
//     v_n^{n+1} = w_n^{n+1} = (m_s v_n* + m_w w_n*) / (m_s + m_w + dt C_n),   C_n = rho c_p A,
// while the tangential dashpot acts on the skeleton only (water carries no shear stress),
//     v_t^{n+1} = m_s v_t* / (m_s + dt C_t),   C_t = rho c_s A,   w_t unchanged.
// Here rho is the saturated density rho_sat = (1 - n) rho_s + n rho_w, c_p the UNDRAINED P-wave
// speed sqrt((M + K_w / n) / rho_sat) and c_s = sqrt(G / rho_sat). This is the Lysmer-Kuhlemeyer
// condition of the undrained mixture, the low-frequency limit of Biot's theory (drag couples the
// phases: wave periods long against rho_w k / (n gamma_w)); there the total traction of an
// outgoing plane wave is exactly -rho_sat c_u v_n. Faster (higher-frequency) Biot P-waves and the
// slow wave are absorbed only approximately. Seed 002 does not give its dashpot's equations.
//
// A body under initial stress or gravity needs the support a fixed face gave it: with
// `free_field: true` the face also carries, as constant nodal forces, the reaction that held the
// body in the first step the face acts (R_I = -f_I, the whole nodal force at its nodes then, of
// each phase), the standard way of switching a statically loaded boundary to a viscous one
// (the static reaction stays, the dashpots take the motion). The body must be at rest and in
// equilibrium at that step (a geostatic initial stress, or the end of a gravity stage); what
// the discrete state does not balance elsewhere still drifts through the dashpots (a geostatic
// column under bspline2, whose quadrature near a free top leaves 0.2 % of the weight
// unbalanced, sinks at 0.2 % of the free drift: tests/test_absorbing.cpp). The reaction is
// checkpointed.
//
// Measured reflections (tests/test_absorbing.cpp, peak reflected over peak incident): a half-sine
// pulse 20 cells long in an elastic bar, 2.6 % (linear, cpdi) to 3.7 % (bspline2), 2.6 % in 2D
// (a fixed face: 98-105 %); the seed 002 column's undrained wave 2.5 % (fixed base: 90 %), and
// 7 % with 100 times its permeability, where the wave is no longer undrained.
#include <algorithm>
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Absorbing : public Boundary<D> {
 public:
  static constexpr const char* name = "absorbing";
  static constexpr const char* summary =
      "viscous absorbing grid face (Lysmer-Kuhlemeyer dashpots rho c_p normal, rho c_s "
      "tangential, implicit; two-phase: impermeable, undrained mixture impedance)";
  static Schema schema() {
    Schema s;
    add_reaction_name(s);
    s.choice("face", face_names(), "grid face carrying the dashpots").required();
    s.real("density", "kg/m^3",
           "mass density rho of the material next to the face (two-phase: saturated density "
           "(1 - n) rho_s + n rho_w)")
        .required()
        .positive();
    s.real("p_wave_speed", "m/s",
           "P-wave speed c_p = sqrt(M / rho) of that material, M = E (1 - nu) / ((1 + nu) "
           "(1 - 2 nu)) the constrained modulus (two-phase: the undrained speed sqrt((M + K_w / n) "
           "/ rho_sat)); normal dashpot rho c_p per unit area")
        .required()
        .positive();
    s.real("s_wave_speed", "m/s",
           "S-wave speed c_s = sqrt(G / rho), G = E / (2 (1 + nu)) (two-phase: G / rho_sat); "
           "tangential dashpot rho c_s per unit area, 0 for none; required in 2D and 3D")
        .non_negative();
    s.boolean("free_field",
              "also carry, as constant nodal forces, the reaction that held the body in the "
              "first step the face acts (a body under initial stress or gravity then does not "
              "drift through the dashpots; it must be at rest and in equilibrium then)")
        .def("false");
    return s;
  }
  explicit Absorbing(const Params& p)
      : params_(p),
        face_(parse_face(p.text("face"))),
        normal_(p.real("density") * p.real("p_wave_speed")),
        tangential_(p.has("s_wave_speed") ? p.real("density") * p.real("s_wave_speed") : 0.0),
        free_field_(p.flag("free_field")) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(face_, D, params_, "face", diag)) return;
    if (D > 1 && !params_.has("s_wave_speed"))
      diag.error(params_.where(), params_.path("s_wave_speed"),
                 "missing required key 's_wave_speed' in " + std::to_string(D) +
                     "D (S-wave speed for the tangential dashpots, m/s; 0 for none)");
    const Grid<D>& g = sim.grid;
    nodes_ = face_nodes(g, face_);
    area_ = face_node_areas(g, face_, nodes_);
  }

  /// The face is the edge of the modelled domain: the dashpots stand for the material beyond it,
  /// whose particles are not modelled, so the particles stay inside (a body pressed onto the
  /// face, which drifts at t / (rho c_p), piles up against it instead of leaving the grid).
  int holds_face(int) const override { return face_index(face_); }
  /// Per node of the face, on the stored box: the dashpots act on complete nodal masses and
  /// velocities, the free-field reaction is each stored copy's own (the same on every rank that
  /// stores the node) and goes into each rank's checkpoint.
  bool runs_on_ranks() const override { return true; }
  bool adds_forces() const override { return free_field_; }

  /// free_field: the reaction of the first step, R = -f at the face's nodes (every component,
  /// each phase), then added to every step's forces.
  void add_forces(const GridForces& f) const override {
    if (!free_field_) return;
    const std::array<NodalVector, 2> force{f.mixture, f.water};
    if (reaction_.empty()) {
      reaction_.resize(size_t(f.count) * nodes_.size() * D);
      size_t j = 0;
      for (int k = 0; k < f.count; ++k)
        for (size_t n : nodes_)
          for (int d = 0; d < D; ++d) reaction_[j++] = -force[size_t(k)].at(n, d);
    }
    size_t j = 0;
    for (int k = 0; k < f.count && j < reaction_.size(); ++k)
      for (size_t n : nodes_)
        for (int d = 0; d < D; ++d) force[size_t(k)].at(n, d) += reaction_[j++];
  }
  bool save_state(std::vector<double>& state) const override {
    if (!free_field_) return false;
    state.push_back(double(reaction_.size()));
    state.insert(state.end(), reaction_.begin(), reaction_.end());
    return true;
  }
  void restore_state(const std::vector<double>& state) override {
    reaction_.assign(state.begin() + 1, state.begin() + 1 + long(state.at(0)));
  }

  /// A dashpot constrains no momentum, force or re-mapped velocity: it acts in the update only.
  void constrain(const NodalVector&) const override {}

  void constrain_grid_update(const GridUpdate& u) const override {
    const double dt = u.dt;
    if (!(dt > 0)) return;
    const int ax = face_.axis;
    const PhaseUpdate& s = u.phases[0];
    for (size_t k = 0; k < nodes_.size(); ++k) {
      const size_t n = nodes_[k];
      const double ms = s.mass.at(n, 0);
      if (!(ms > 0)) continue;  // the scheme left this node at rest
      const double cn = dt * normal_ * area_[k], ct = dt * tangential_ * area_[k];
      for (int d = 0; d < D; ++d) {
        if (d == ax && u.count == 2) continue;  // normal of a two-phase update: below
        damp(s, n, d, ms / (ms + (d == ax ? cn : ct)), dt);
      }
      if (u.count == 2) {
        // Impermeable: solid and water share the normal velocity; mixture dashpot on it.
        const PhaseUpdate& w = u.phases[1];
        const double mw = w.mass.at(n, 0);
        const double vs = s.velocity.at(n, ax), vw = w.velocity.at(n, ax);
        const double vn = (ms * vs + std::max(mw, 0.0) * vw) / (ms + std::max(mw, 0.0) + cn);
        s.velocity.at(n, ax) = vn;
        s.acceleration.at(n, ax) += (vn - vs) / dt;
        w.velocity.at(n, ax) = vn;
        w.acceleration.at(n, ax) += (vn - vw) / dt;
      }
    }
  }

  const std::vector<size_t>* reaction_nodes() const override { return &nodes_; }

 private:
  /// v <- factor v for component d of node n, with a consistent acceleration.
  static void damp(const PhaseUpdate& p, size_t n, int d, double factor, double dt) {
    const double before = p.velocity.at(n, d), after = factor * before;
    p.velocity.at(n, d) = after;
    p.acceleration.at(n, d) += (after - before) / dt;
  }

  Params params_;
  Face face_;
  double normal_, tangential_;  // rho c_p and rho c_s (Pa s/m)
  bool free_field_;
  mutable std::vector<double> reaction_;  // free_field: R per phase, node, component (N)
  std::vector<size_t> nodes_;
  std::vector<double> area_;  // tributary face area per node (m^(D-1))
};

LOAM_REGISTER(Boundary, Absorbing)

}  // namespace loam
