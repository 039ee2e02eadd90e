#pragma once
// Building blocks of an explicit MPM step, shared by the schemes so that each scheme's step()
// reads as a list of named phases (Karamelo's MUSL::run, ExaMPM's step()): per-thread block
// scratch, grid zeroing and node loops, the FLIP/PIC blend of the grid-to-particle update, the
// velocity gradient L = sum_I v_I (x) grad N_I, and the volume and deformation-gradient update
// V <- det(I + L dt) V, F <- (I + L dt) F. Each is an inline function on one particle or one
// stencil entry, so a scheme's fused loops stay fused (one pass over the stencil).
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "force_inline.hpp"
#include "particles.hpp"
#include "shape_function.hpp"
#include "tensor.hpp"
#include "thread_scratch.hpp"

namespace loam {

/// What a particle-to-grid pass scatters: mass and momentum, the forces, or both (USF scatters
/// them in two passes around the stress update; USL and MUSL in one).
enum class Scatter { kMomentum, kForce, kMomentumAndForce };
constexpr bool scatters_momentum(Scatter s) {
  return s != Scatter::kForce;
}
constexpr bool scatters_force(Scatter s) {
  return s != Scatter::kMomentum;
}

/// What a grid-to-particle velocity pass does besides the FLIP/PIC update of the velocities:
/// re-map the new momenta to the grid (MUSL's first pass), nothing more (USL with APIC), or move
/// the particles with the updated grid velocity (USF).
enum class VelocityPass { kRemap, kUpdate, kUpdateAndMove };
constexpr bool remaps(VelocityPass p) {
  return p == VelocityPass::kRemap;
}
constexpr bool moves(VelocityPass p) {
  return p == VelocityPass::kUpdateAndMove;
}

/// The order of an explicit step's grid update and stress update (Sulsky et al. 1995; Bardenhagen
/// 2002): update stress last, modified update stress last, update stress first.
enum class UpdateOrder { kUsl, kMusl, kUsf };

/// What every scheme's block loop needs per thread: the stencil of the block, the velocity
/// gradients of the block in MaterialBatch layout (L[(i*D + j)*kBlock + p]), and the largest
/// particle speed squared seen in the step. A scheme derives from it for its own buffers.
template <int D>
struct alignas(64) BlockScratch {
  StencilBlock<D> stencil;
  std::vector<double> L;
  double max_v2 = 0;
};

/// One scratch per thread, sized for `nodes_per_particle` stencil entries; `init` sizes what a
/// derived scratch adds.
template <class S, int D = decltype(S::stencil)::dimension, class Init>
std::vector<std::unique_ptr<S>> make_block_scratch(int threads, int nodes_per_particle,
                                                   Init&& init) {
  return per_thread_scratch<S>(threads, [&](S& s) {
    s.stencil.allocate(nodes_per_particle);
    s.L.assign(size_t(D * D * kBlock), 0.0);
    init(s);
  });
}

template <class S>
void reset_max_speed(std::vector<std::unique_ptr<S>>& scratch) {
  for (auto& s : scratch) s->max_v2 = 0;
}
/// The largest particle speed of the step, over all threads.
template <class S>
double max_speed(const std::vector<std::unique_ptr<S>>& scratch) {
  double m = 0;
  for (const auto& s : scratch) m = std::max(m, s->max_v2);
  return std::sqrt(m);
}

/// Zero a nodal array on all threads (first-touch friendly, static schedule).
inline void zero_nodes(std::vector<double>& v, int threads) {
  const long n = long(v.size());
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long i = 0; i < n; ++i) v[size_t(i)] = 0.0;
}

/// f(node) for every node, in parallel (static schedule).
template <class F>
void for_each_node(size_t num_nodes, int threads, F&& f) {
  const long n = long(num_nodes);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long i = 0; i < n; ++i) f(size_t(i));
}

/// 1 / m for a node lighter than numerics.mass_tolerance. Such a node gets no acceleration
/// (f / m is unbounded there: f holds V sigma grad N, which does not vanish with the weight) but
/// keeps its particles' mean velocity p / m: a particle on a node line weighs round-off on the
/// nodes behind it, and a zero velocity there would break sum_I grad N_I = 0 in its velocity
/// gradient (a rigidly translating block lost 0.6 % of its volume in one step;
/// tests/test_invariance.cpp). 0 where m is no normal positive number (no mass, or a round-off
/// sum too small for p / m to resolve).
inline double light_node_velocity_scale(double m) {
  return m > 1e-290 ? 1 / m : 0.0;
}

/// A node's velocity from its momentum p and mass m: p / m, for a light node too
/// (light_node_velocity_scale); 0 without mass.
LOAM_FORCE_INLINE double node_velocity(double p, double m, double mass_tolerance) {
  return m > mass_tolerance ? p / m : p * light_node_velocity_scale(m);
}

/// The FLIP/PIC blend of the particle velocity update: FLIP adds the interpolated grid
/// acceleration to the particle's own velocity (no dissipation, noisy where nodes are nearly
/// empty), PIC takes the interpolated grid velocity (smooth, dissipative); `flip` in [0, 1].
LOAM_FORCE_INLINE double flip_pic(double flip, double v, double dt, double a_grid, double v_grid) {
  return flip * (v + dt * a_grid) + (1.0 - flip) * v_grid;
}

/// |v + dt a_grid|^2 - |v_new|^2 of one component: twice the kinetic energy per unit mass that a
/// blended update v_new took against FLIP's (the energy balance's D_transfer,
/// framework/energy_ledger.hpp).
LOAM_FORCE_INLINE double transfer_loss(double v, double dt, double a_grid, double v_new) {
  const double v_flip = v + dt * a_grid;
  return v_flip * v_flip - v_new * v_new;
}

/// Stencil entry kp of particle p (kp = k * kBlock + p) adds v_I (x) grad N_I to l.
template <int D>
LOAM_FORCE_INLINE void add_velocity_gradient(double (&l)[D][D], const double* v_node,
                                             const StencilBlock<D>& st, size_t k, int p) {
  for (int j = 0; j < D; ++j) {
    const double gj = st.grad[(k * D + size_t(j)) * kBlock + size_t(p)];
    for (int i = 0; i < D; ++i) l[i][j] += v_node[i] * gj;
  }
}

/// Store particle p's velocity gradient in the block layout the materials read.
template <int D>
LOAM_FORCE_INLINE void store_velocity_gradient(const double (&l)[D][D], double* L, int p) {
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) L[size_t(i * D + j) * kBlock + size_t(p)] = l[i][j];
}

/// The columns of the deformation gradient from particle b on, or nulls when no plugin
/// requested F (Simulation::deformation_gradient < 0): then it costs nothing.
template <int D>
std::array<double*, D * D> deformation_gradient_block(Particles<D>& P, int handle, size_t b) {
  std::array<double*, D * D> F{};
  if (handle >= 0)
    for (int c = 0; c < D * D; ++c) F[size_t(c)] = P.col(handle, c) + b;
  return F;
}

/// V <- det(I + L dt) V and, when F is stored, F <- (I + L dt) F for particle p of the block;
/// returns the volume ratio J = det(I + L dt).
template <int D>
LOAM_FORCE_INLINE double update_volume_and_deformation(const double (&l)[D][D], double dt,
                                                       double& V,
                                                       const std::array<double*, D * D>& F, int p) {
  const double J = det_increment<D>(l, dt);
  V *= J;
  if (F[0]) update_deformation_gradient<D>(F, l, dt, p);
  return J;
}

}  // namespace loam
