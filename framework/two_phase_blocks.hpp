#pragma once
// Building blocks shared by the two-phase schemes (schemes/two_phase_single_point.cpp, one point
// carrying both phases; schemes/two_phase_double_point.cpp, solid and liquid points): the
// node-wise implicit drag solve, the re-solve of a phase whose partner a boundary condition held,
// and the fastest wave of the drag-free two-phase equations for the time step. Each acts on one
// node component or one particle, so the schemes' node loops stay theirs.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "affine_transfer.hpp"
#include "diagnostics.hpp"
#include "force_inline.hpp"
#include "simulation.hpp"
#include "step_blocks.hpp"

namespace loam {

/// New solid and water velocities of one node component.
struct PhaseVelocities {
  double solid, water;
};

/// The momentum equations of the two phases of a node, drag implicit (framework/drag.hpp has the
/// convention: force -Q (w - v) on the water, +Q (w - v) on the skeleton):
///   (m_w/dt + Q) w' - Q v'           = b_water   (= m_w w/dt + F_w)
///   -Q w'          + (m_s/dt + Q) v' = b_solid   (= m_s v/dt + F_s)
/// A 2x2 solve per node and component, unconditionally stable in Q: a low permeability (a large
/// Q) does not shrink the time step, it ties the phases (w' -> v' as Q -> inf).
LOAM_FORCE_INLINE PhaseVelocities solve_drag_implicit(double ms, double mw, double Q, double dt,
                                                      double b_solid, double b_water) {
  const double a11 = mw / dt + Q, a22 = ms / dt + Q;
  const double det = a11 * a22 - Q * Q;
  return {(a11 * b_solid + Q * b_water) / det, (b_water * a22 + Q * b_solid) / det};
}

/// A condition that holds one phase of a node component and leaves the other free (a fixed
/// skeleton on a drained face: fixed + drained, or fixed with phase: solid; a water-only
/// fixity) changed that phase's velocity after the coupled solve, in which it was still free.
/// The free phase must see the held velocity through the drag: its row is solved again with
/// the partner's new velocity, e.g. for the water
///   (m_w/dt + Q) w'' = m_w w/dt + F_w + Q v'_c   =>   w'' = w' + Q (v'_c - v') / (m_w/dt + Q).
/// Without this the water leaving a fixed drained base is dragged by the fictitious free-solid
/// velocity of the solve (over-drainage near the face). A component whose phases both changed
/// (both held, tied by impermeable, damped by a dashpot) is left as its conditions set it.
/// v, w: the constrained velocities, a_s, a_w their accelerations; *_solved: before the
/// conditions.
LOAM_FORCE_INLINE void follow_held_phase(double ms, double mw, double Q, double dt, double v_solved,
                                         double w_solved, double& v, double& w, double& a_s,
                                         double& a_w) {
  const double dv = v - v_solved, dw = w - w_solved;
  if (dv != 0.0 && dw == 0.0) {
    const double c = Q * dv / (mw / dt + Q);
    w += c;
    a_w += c / dt;
  } else if (dw != 0.0 && dv == 0.0) {
    const double c = Q * dw / (ms / dt + Q);
    v += c;
    a_s += c / dt;
  }
}

/// Where a two-phase scheme's node record keeps what the grid passes below read: offsets of the
/// solid and water masses, the drag coefficient Q, the solid and water velocities and
/// accelerations (D values each), the nodal porosity, and the record's length.
struct TwoPhaseRecord {
  int solid_mass, water_mass, drag, solid_velocity, water_velocity, solid_acceleration,
      water_acceleration, porosity, stride;
};

/// Which masses make a two-phase node light (below mass_tolerance), and so how it is solved.
enum class PhaseNodes {
  /// Single point: the water lives on the solid's points and the force given for the solid is
  /// the mixture's (F_s = F - F_w). A node is light when its solid is: both phases keep their
  /// points' mean velocities (water without mass that of the solid), it gets no drag and no
  /// porosity. Water too light to solve for moves with the solid.
  kMixture,
  /// Double point: each phase by its own mass. A node may hold one phase alone, which is
  /// integrated by itself; a light phase keeps its points' mean velocity.
  kSeparate,
};

/// One component of a node's two momentum equations with the drag implicit
/// (solve_drag_implicit), from the momenta p_s, p_w and the forces F, F_w (F the mixture's for
/// kMixture, the solid's for kSeparate): the new velocities in vn, wn, their accelerations in
/// a_s, a_w. A light phase keeps its points' mean velocity p / m without acceleration
/// (light_node_velocity_scale).
template <PhaseNodes KIND>
LOAM_FORCE_INLINE void solve_two_phase_component(double ms, double mw, double Q, double dt,
                                                 double tol, double ps, double pw, double F,
                                                 double Fw, double& vn, double& wn, double& a_s,
                                                 double& a_w) {
  if constexpr (KIND == PhaseNodes::kMixture) {
    if (ms <= tol) {
      const double sw = light_node_velocity_scale(mw);
      vn = ps * light_node_velocity_scale(ms);
      wn = sw > 0 ? pw * sw : vn;
      a_s = a_w = 0.0;
      return;
    }
    const double v = ps / ms, w = mw > tol ? pw / mw : v;
    const auto s = solve_drag_implicit(ms, mw, Q, dt, ms * v / dt + F - Fw, mw * w / dt + Fw);
    vn = s.solid, wn = mw <= tol ? s.solid : s.water;
    a_s = (vn - v) / dt;
    a_w = (wn - w) / dt;
  } else {
    const bool has_s = ms > tol, has_w = mw > tol;
    const double v = has_s ? ps / ms : 0.0, w = has_w ? pw / mw : 0.0;
    vn = ps * light_node_velocity_scale(ms), wn = pw * light_node_velocity_scale(mw);
    if (has_s && has_w) {
      const auto s = solve_drag_implicit(ms, mw, Q, dt, ms * v / dt + F, mw * w / dt + Fw);
      vn = s.solid, wn = s.water;
    } else if (has_s) {
      vn = v + dt * F / ms;
    } else if (has_w) {
      wn = w + dt * Fw / mw;
    }
    a_s = has_s ? (vn - v) / dt : 0.0;
    a_w = has_w ? (wn - w) / dt : 0.0;
  }
}

/// The coupled grid solve of a two-phase scheme at every node: each record's momenta and forces
/// become the new velocities and their accelerations (solve_two_phase_component); `solved` keeps
/// the velocities (solid then water, 2 D values per node) for follow_held_phases.
template <int D, PhaseNodes KIND>
void solve_two_phase_nodes(const Simulation<D>& sim, double* records, const TwoPhaseRecord& k,
                           double* solved, double dt) {
  const double tol = sim.mass_tolerance;
  for_each_node(sim.grid.num_nodes, sim.threads, [=](size_t i) {
    double* r = records + i * size_t(k.stride);
    double* sv = solved + i * 2 * D;
    const double ms = r[k.solid_mass], mw = r[k.water_mass], Q = r[k.drag];
    for (int d = 0; d < D; ++d) {
      double& v = r[k.solid_velocity + d];
      double& w = r[k.water_velocity + d];
      double& a_s = r[k.solid_acceleration + d];
      double& a_w = r[k.water_acceleration + d];
      solve_two_phase_component<KIND>(ms, mw, Q, dt, tol, v, w, a_s, a_w, v, w, a_s, a_w);
      sv[d] = v;
      sv[D + d] = w;
    }
    if (KIND == PhaseNodes::kMixture && ms <= tol) r[k.drag] = r[k.porosity] = 0.0;
  });
}

/// follow_held_phase at every node with both phases and drag, component by component, after the
/// boundary conditions; `solved` holds the velocities of the coupled solve (solid then water,
/// 2 D values per node).
template <int D>
void follow_held_phases(double* records, const TwoPhaseRecord& k, const double* solved,
                        size_t num_nodes, int threads, double mass_tolerance, double dt) {
  for_each_node(num_nodes, threads, [=](size_t i) {
    double* r = records + i * size_t(k.stride);
    const double* s = solved + i * 2 * D;
    const double ms = r[k.solid_mass], mw = r[k.water_mass], Q = r[k.drag];
    if (ms <= mass_tolerance || mw <= mass_tolerance || !(Q > 0)) return;
    for (int d = 0; d < D; ++d)
      follow_held_phase(ms, mw, Q, dt, s[d], s[D + d], r[k.solid_velocity + d],
                        r[k.water_velocity + d], r[k.solid_acceleration + d],
                        r[k.water_acceleration + d]);
  });
}

/// The drag's dissipation Q |w' - v'|^2 dt of every node with both phases, with the velocities
/// the boundary conditions left: a fixed base holds both phases, and the relative velocity of
/// the unconstrained solve there is not a flow (it is the base's reaction).
template <int D>
void count_drag_dissipation(Simulation<D>& sim, const double* records, const TwoPhaseRecord& k,
                            double dt) {
  const double tol = sim.mass_tolerance;
  for_each_node(sim.grid.num_nodes, sim.threads, [&](size_t i) {
    const double* r = records + i * size_t(k.stride);
    const double Q = r[k.drag];
    if (r[k.solid_mass] <= tol || r[k.water_mass] <= tol || !(Q > 0)) return;
    double slip2 = 0;
    for (int d = 0; d < D; ++d) {
      const double s = r[k.water_velocity + d] - r[k.solid_velocity + d];
      slip2 += s * s;
    }
    sim.ledger.add_drag(i, dt * Q * slip2);
  });
}

/// The boundary conditions on both phases of the records after the coupled solve
/// (Simulation::constrain_update, with the nodal masses and porosity), then the re-solve of a
/// free phase against a held partner (follow_held_phases).
template <int D>
void constrain_two_phase_update(Simulation<D>& sim, double* records, const TwoPhaseRecord& k,
                                const double* solved, double dt) {
  GridUpdate u;
  const int S = k.stride;
  u.phases[0] = {NodalVector{records, S, k.solid_velocity},
                 NodalVector{records, S, k.solid_acceleration},
                 NodalVector{records, S, k.solid_mass}};
  u.phases[1] = {NodalVector{records, S, k.water_velocity},
                 NodalVector{records, S, k.water_acceleration},
                 NodalVector{records, S, k.water_mass}};
  u.count = 2;
  u.dt = dt;
  u.porosity = NodalVector{records, S, k.porosity};
  sim.constrain_update(u, [&] {
    follow_held_phases<D>(records, k, solved, sim.grid.num_nodes, sim.threads, sim.mass_tolerance,
                          dt);
  });
  if (sim.ledger.enabled) count_drag_dissipation(sim, records, k, dt);
}

/// What a node without water mass gives the water's re-mapped velocity: nothing (a double-point
/// liquid point is the water; no point, no water), or the solid's (the single-point mixture
/// carries its water with the skeleton).
enum class MasslessWater { kNone, kFollowsSolid };

/// The MUSL re-map's momenta (solid then water, 2 D values per node) to velocities with the
/// node masses of the step (node_velocity: light nodes too), then constrained like the update.
template <int D>
void remapped_two_phase_velocities(Simulation<D>& sim, const double* records,
                                   const TwoPhaseRecord& k, std::vector<double>& remap,
                                   MasslessWater massless) {
  const double tol = sim.mass_tolerance;
  double* rm = remap.data();
  for_each_node(sim.grid.num_nodes, sim.threads, [=](size_t i) {
    const double* g = records + i * size_t(k.stride);
    const double ms = g[k.solid_mass], mw = g[k.water_mass];
    double* r = rm + i * 2 * D;
    const bool has_water =
        massless == MasslessWater::kNone || mw > tol || light_node_velocity_scale(mw) > 0;
    for (int d = 0; d < D; ++d) {
      r[d] = node_velocity(r[d], ms, tol);
      r[D + d] = has_water ? node_velocity(r[D + d], mw, tol) : r[d];
    }
  });
  sim.constrain(NodalVector{rm, 2 * D, 0});
  sim.constrain(NodalVector{rm, 2 * D, D}, 1);
}

/// The affine transfers (transfer: apic or tpic) in a two-phase scheme: both are MUSL or USL,
/// never USF, so linear tents (which need USF's gradient, framework/affine_transfer.hpp) and the
/// shapes AffineTransfer does not fit are refused at `transfer`.
template <int D>
void refuse_affine_shape(const AffineTransfer<D>& affine, const ShapeFunction<D>& shape,
                         const std::string& transfer, const Location& where,
                         const std::string& path, Diagnostics& diag) {
  if (affine.needs_usf() || !AffineTransfer<D>::fits(shape))
    diag.error(where, path,
               "transfer: " + transfer +
                   " in this scheme needs gimp, bspline2 or cpdi (linear tents take the affine "
                   "transfers with update: usf only, which this scheme does not offer: "
                   "framework/affine_transfer.hpp)");
}

/// Square of the fastest wave speed of the undamped (drag-free) two-phase equations: the largest
/// eigenvalue c^2 of K - c^2 R = 0 with the stiffness and mass matrices of the two phases
///   K = [ M + (1 - n)^2 K_w / n   (1 - n) K_w ]    R = diag((1 - n) rho_s, n rho_w),
///       [ (1 - n) K_w             n K_w       ]
/// (M the skeleton's constrained modulus, rho_d = (1 - n) rho_s): c^2 = (b + sqrt(b^2 - 4 a c0))
/// / (2 a) with a = det R, b = K11 R22 + K22 R11, c0 = det K = M n K_w. The drag couples the
/// phases and slows the wave towards the undrained one, sqrt((M + K_w/n) / rho_sat), but with a
/// large permeability (or the explicit part of the update) the fast wave is this one: 12 %
/// faster for the consolidation column of the FEM-and-MPM large-strain consolidation paper (seed
/// 001 in docs/verification.md; 1857 vs 1664 m/s), where the undrained speed let USL diverge at
/// cfl 0.72.
inline double fast_wave_speed2(double M, double n, double rho_d, double Kw, double rho_w) {
  const double K11 = M + (1 - n) * (1 - n) * Kw / n, K22 = n * Kw;
  const double R11 = rho_d, R22 = n * rho_w;
  const double a = R11 * R22, b = K11 * R22 + K22 * R11, c0 = M * n * Kw;
  return (b + std::sqrt(std::max(0.0, b * b - 4 * a * c0))) / (2 * a);
}

/// The largest fast_wave_speed2 over the points of a set whose `mass` is the solid mass
/// (1 - n) rho_s V and `porosity` their porosity field, with each material's constrained modulus
/// from its P-wave speed (M = c^2 rho_d), for pore water (K_w, rho_w); 0 for an empty set.
template <int D>
double max_fast_wave_speed2(const Simulation<D>& sim, const ParticleSet<D>& set, int porosity,
                            double Kw, double rho_w) {
  const auto& P = set.particles;
  double c2 = 0;
  for (size_t m = 0; m < sim.materials.size(); ++m) {
    const auto& r = set.partition.material_ranges[m];
    const double cd = sim.material_wave_speed(set, m);  // over the ranks: every rank calls it
    for (size_t i = r.begin; i < r.end; ++i) {
      const double rho_d = P.col(P.mass)[i] / P.col(P.volume)[i];  // (1 - n) rho_s
      c2 = std::max(c2, fast_wave_speed2(cd * cd * rho_d, P.col(porosity)[i], rho_d, Kw, rho_w));
    }
  }
  return c2;
}

}  // namespace loam
