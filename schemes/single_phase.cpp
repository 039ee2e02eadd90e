// Single-phase explicit MPM (Sulsky et al. 1994; update variants after Bardenhagen 2002 and
// Nairn 2003): lumped mass, FLIP/PIC blend for the particle velocity, stress update before the
// force computation (USF), after the grid update (USL), or after re-mapping the updated particle
// momentum to the grid (MUSL, the default; least noisy for near-empty nodes).
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"
#include "framework/thread_scratch.hpp"

namespace loam {

template <int D>
class SinglePhase : public Scheme<D> {
 public:
  static constexpr const char* name = "single_phase";
  static constexpr const char* summary =
      "one-phase explicit MPM (dry soil, solids, fluids) with USF, USL or MUSL stress update";
  static Schema schema() {
    Schema s;
    s.choice("update", {"musl", "usl", "usf"},
             "when stress is updated: musl (after re-mapping particle momentum), usl (after the "
             "grid update), usf (before forces)")
        .def("musl");
    add_flip_param(s);
    return s;
  }
  explicit SinglePhase(const Params& p) : update_(p.text("update")), flip_(p.real("flip")) {}

  void setup(Simulation<D>& sim, Diagnostics&) override {
    node_.assign(sim.grid.num_nodes * S, 0.0);
    vel_.assign(sim.grid.num_nodes * D, 0.0);
    const int npp = sim.shape->nodes_per_particle();
    scratch_ = per_thread_scratch<Scratch>(sim.threads, [&](Scratch& s) {
      s.stencil.allocate(npp);
      s.L.assign(size_t(D * D * kBlock), 0.0);
    });
  }

  std::vector<GridFieldView> grid_fields() const override {
    return {{"mass", 1, node_.data(), S, 0},
            {"velocity", D, vel_.data(), D, 0},
            {"acceleration", D, node_.data(), S, 1 + D}};
  }

  void step(Simulation<D>& sim, double dt) override {
    // Plugins may request F after this scheme's set-up; look it up once per step.
    deformation_gradient_ = sim.particles.find("deformation_gradient");
    with_stencil_size<D>(sim.shape->nodes_per_particle(), [&](auto npp) {
      constexpr int NPP = decltype(npp)::value;
      if (update_ == "usf")
        step_usf<NPP>(sim, dt);
      else
        step_usl_musl<NPP>(sim, dt, update_ == "musl");
    });
  }

 private:
  // Node record for the scatter: mass, momentum (D), force (D). After integration the momentum
  // slot holds the updated velocity and the force slot the acceleration.
  static constexpr int S = 1 + 2 * D;
  static constexpr int NS = Particles<D>::NS;
  std::string update_;
  double flip_;
  int deformation_gradient_ = -1;
  std::vector<double> node_;  // num_nodes * S
  std::vector<double> vel_;   // num_nodes * D: velocity used for the velocity gradient
  struct alignas(64) Scratch {
    StencilBlock<D> stencil;
    std::vector<double> L;
    double max_v2 = 0;
  };
  std::vector<std::unique_ptr<Scratch>> scratch_;

  NodalVector node_vector(int offset) { return NodalVector{node_.data(), S, offset}; }
  NodalVector vel_vector() { return NodalVector{vel_.data(), D, 0}; }

  void zero(std::vector<double>& v, int threads) {
    const long n = long(v.size());
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i) v[size_t(i)] = 0.0;
  }

  /// Particle-to-grid: mass and momentum (MOMENTUM), internal, gravity and external forces (FORCE).
  template <int NPP, bool MOMENTUM, bool FORCE>
  void scatter(Simulation<D>& sim, size_t b, int count, int thread) {
    Particles<D>& P = sim.particles;
    StencilBlock<D>& st = scratch_[size_t(thread)]->stencil;
    sim.shape->evaluate(sim.grid, P, b, count, st);
    const int npp = NPP ? NPP : st.npp;
    const double* m = P.col(P.mass) + b;
    const double* V = P.col(P.volume) + b;
    std::array<const double*, D> v{}, fe{};
    std::array<const double*, NS> sig{};
    for (int d = 0; d < D; ++d) {
      v[size_t(d)] = P.col(P.velocity, d) + b;
      fe[size_t(d)] = sim.external_force >= 0 ? P.col(sim.external_force, d) + b : nullptr;
    }
    for (int c = 0; c < NS; ++c) sig[size_t(c)] = P.col(P.stress, c) + b;
    double* g = node_.data();
    for (int p = 0; p < count; ++p) {
      double mv[D], body[D], sv[D][D];
      for (int d = 0; d < D; ++d) {
        mv[d] = m[p] * v[size_t(d)][p];
        body[d] = m[p] * sim.gravity[size_t(d)] + (fe[size_t(d)] ? fe[size_t(d)][p] : 0.0);
        for (int j = 0; j < D; ++j) sv[d][j] = V[p] * sig[size_t(voigt_index(d, j))][p];
      }
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const double w = st.w[kp];
        double* r = g + size_t(st.node[kp]) * S;
        if constexpr (MOMENTUM) {
          r[0] += w * m[p];
          for (int d = 0; d < D; ++d) r[1 + d] += w * mv[d];
        }
        if constexpr (FORCE) {
          double gr[D];
          for (int j = 0; j < D; ++j)
            gr[j] = st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
          for (int d = 0; d < D; ++d) {
            double f = w * body[d];
            for (int j = 0; j < D; ++j) f -= sv[d][j] * gr[j];  // f_int = -V sigma . grad N
            r[1 + D + d] += f;
          }
        }
      }
    }
  }

  /// Nodal forces to updated velocity and acceleration, with loads, damping and constraints.
  void integrate(Simulation<D>& sim, double dt) {
    sim.apply_grid_loads(node_vector(1 + D));
    GridForces forces;
    forces.mixture = node_vector(1 + D);
    sim.apply_boundary_forces(forces);
    sim.apply_damping(
        NodeForces{node_.data(), node_vector(1), node_vector(1 + D), sim.grid.num_nodes, S});
    const long n = long(sim.grid.num_nodes);
    const double tol = sim.mass_tolerance;
    double* g = node_.data();
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long i = 0; i < n; ++i) {
      double* r = g + size_t(i) * S;
      if (r[0] > tol) {
        const double inv = 1.0 / r[0];
        for (int d = 0; d < D; ++d) {
          const double a = r[1 + D + d] * inv;
          r[1 + d] = r[1 + d] * inv + dt * a;  // v^{n+1} = (p + dt f) / m
          r[1 + D + d] = a;
        }
      } else {
        for (int d = 0; d < 2 * D; ++d) r[1 + d] = 0.0;
      }
    }
    GridUpdate u;
    u.phases[0] = {node_vector(1), node_vector(1 + D), node_vector(0)};
    u.dt = dt;
    sim.constrain_update(u);
  }

  /// Velocity from momentum in vel_ (MUSL re-map, USF), constrained.
  void momentum_to_velocity(Simulation<D>& sim, const double* momentum, int stride, int offset) {
    const long n = long(sim.grid.num_nodes);
    const double tol = sim.mass_tolerance;
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long i = 0; i < n; ++i) {
      const double m = node_[size_t(i) * S];
      for (int d = 0; d < D; ++d)
        vel_[size_t(i) * D + size_t(d)] =
            m > tol ? momentum[size_t(i) * size_t(stride) + size_t(offset + d)] / m : 0.0;
    }
    sim.constrain(vel_vector());
  }

  /// Grid-to-particle velocity update (FLIP/PIC blend). With REMAP, scatter the new particle
  /// momentum into vel_ (MUSL). With MOVE, also move particles with the updated grid velocity
  /// (never across a held face: Simulation::held_faces).
  template <int NPP, bool REMAP, bool MOVE>
  void update_velocity(Simulation<D>& sim, double dt, size_t b, int count, int thread) {
    Particles<D>& P = sim.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    StencilBlock<D>& st = sc.stencil;
    sim.shape->evaluate(sim.grid, P, b, count, st);
    const int npp = NPP ? NPP : st.npp;
    const double* m = P.col(P.mass) + b;
    std::array<double*, D> v{}, x{};
    for (int d = 0; d < D; ++d) {
      v[size_t(d)] = P.col(P.velocity, d) + b;
      x[size_t(d)] = P.col(P.position, d) + b;
    }
    const double* g = node_.data();
    const double flip = flip_;
    double max_v2 = sc.max_v2;
    for (int p = 0; p < count; ++p) {
      double a[D] = {}, vn[D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const double w = st.w[kp];
        const double* r = g + size_t(st.node[kp]) * S;
        for (int d = 0; d < D; ++d) {
          vn[d] += w * r[1 + d];
          a[d] += w * r[1 + D + d];
        }
      }
      double v2 = 0;
      for (int d = 0; d < D; ++d) {
        double& vp = v[size_t(d)][p];
        vp = flip * (vp + dt * a[d]) + (1.0 - flip) * vn[d];
        v2 += vp * vp;
        if constexpr (MOVE) x[size_t(d)][p] = sim.held_faces.moved(d, x[size_t(d)][p], dt * vn[d]);
      }
      max_v2 = std::max(max_v2, v2);
      if constexpr (REMAP) {
        for (int k = 0; k < npp; ++k) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          const double wm = st.w[kp] * m[p];
          double* r = vel_.data() + size_t(st.node[kp]) * D;
          for (int d = 0; d < D; ++d) r[d] += wm * v[size_t(d)][p];
        }
      }
    }
    sc.max_v2 = max_v2;
  }

  /// What the gradient pass does besides the velocity gradient, volume and stress update.
  enum class Gradient {
    kRemapped,  // MUSL: L from the re-mapped velocity vel_; move with the updated grid velocity
    kCurrent,   // USF: L from vel_ (velocity at t^n); particles do not move here
    kUpdated,   // USL: L, move and FLIP update all from the updated grid record, in one pass
  };

  /// Velocity gradient, volume update, optional move / velocity update, and the material's
  /// stress update for one block.
  template <int NPP, Gradient MODE>
  void update_stress(Simulation<D>& sim, double dt, size_t b, int count, int thread) {
    constexpr bool kMove = MODE != Gradient::kCurrent;
    constexpr bool kFromRecord = MODE == Gradient::kUpdated;
    Particles<D>& P = sim.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    StencilBlock<D>& st = sc.stencil;
    sim.shape->evaluate(sim.grid, P, b, count, st);
    const int npp = NPP ? NPP : st.npp;
    double* L = sc.L.data();
    double* V = P.col(P.volume) + b;
    std::array<double*, D> x{}, v{};
    for (int d = 0; d < D; ++d) {
      x[size_t(d)] = P.col(P.position, d) + b;
      v[size_t(d)] = P.col(P.velocity, d) + b;
    }
    const double* g = node_.data();
    std::array<double*, D * D> F{};  // deformation gradient, if some plugin requested it
    if (deformation_gradient_ >= 0)
      for (int c = 0; c < D * D; ++c) F[size_t(c)] = P.col(deformation_gradient_, c) + b;
    // Source of the velocity field whose gradient is taken.
    const double* vel = kFromRecord ? node_.data() + 1 : vel_.data();
    const size_t vstride = kFromRecord ? S : D;
    const double flip = flip_;
    double max_v2 = sc.max_v2;
    for (int p = 0; p < count; ++p) {
      double l[D][D] = {}, vn[D] = {}, a[D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const size_t n = size_t(st.node[kp]);
        const double* vv = vel + n * vstride;
        for (int j = 0; j < D; ++j) {
          const double gj = st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
          for (int i = 0; i < D; ++i) l[i][j] += vv[i] * gj;
        }
        if constexpr (kMove) {
          const double w = st.w[kp];
          for (int d = 0; d < D; ++d) vn[d] += w * g[n * S + 1 + size_t(d)];
          if constexpr (kFromRecord)
            for (int d = 0; d < D; ++d) a[d] += w * g[n * S + 1 + D + size_t(d)];
        }
      }
      for (int i = 0; i < D; ++i)
        for (int j = 0; j < D; ++j) L[size_t(i * D + j) * kBlock + size_t(p)] = l[i][j];
      // V^{n+1} = det(I + L dt) V^n
      V[p] *= det_increment(l, dt);
      if (F[0]) update_deformation_gradient(F, l, dt, p);
      if constexpr (kMove)
        for (int d = 0; d < D; ++d)
          x[size_t(d)][p] = sim.held_faces.moved(d, x[size_t(d)][p], dt * vn[d]);
      if constexpr (kFromRecord) {
        double v2 = 0;
        for (int d = 0; d < D; ++d) {
          double& vp = v[size_t(d)][p];
          vp = flip * (vp + dt * a[d]) + (1.0 - flip) * vn[d];
          v2 += vp * vp;
        }
        max_v2 = std::max(max_v2, v2);
      }
    }
    sc.max_v2 = max_v2;
    sim.update_block_stress(b, count, dt, L);
  }

  void reset_max_speed() {
    for (auto& s : scratch_) s->max_v2 = 0;
  }
  void store_max_speed(Simulation<D>& sim) {
    double m = 0;
    for (auto& s : scratch_) m = std::max(m, s->max_v2);
    sim.max_speed = std::sqrt(m);
  }

  template <int NPP>
  void step_usl_musl(Simulation<D>& sim, double dt, bool musl) {
    sim.timed("grid", [&] { zero(node_, sim.threads); });
    sim.timed("p2g", [&] {
      sim.scatter_blocks([&](size_t b, int c, int t) { scatter<NPP, true, true>(sim, b, c, t); });
    });
    sim.timed("grid", [&] { integrate(sim, dt); });
    reset_max_speed();
    if (musl) {
      // MUSL: re-map the updated particle momentum; the velocity gradient uses that field, and
      // particles move with the grid velocity of the update (Sulsky 1995).
      sim.timed("grid", [&] { zero(vel_, sim.threads); });
      sim.timed("g2p_velocity_remap", [&] {
        sim.scatter_blocks(
            [&](size_t b, int c, int t) { update_velocity<NPP, true, false>(sim, dt, b, c, t); });
      });
      sim.timed("grid", [&] { momentum_to_velocity(sim, vel_.data(), D, 0); });
      sim.timed("g2p_gradient_stress", [&] {
        sim.gather_blocks([&](size_t b, int c, int t) {
          update_stress<NPP, Gradient::kRemapped>(sim, dt, b, c, t);
        });
      });
    } else {
      // USL: gradient, move and velocity update from the updated grid record in one pass.
      sim.timed("g2p_gradient_stress", [&] {
        sim.gather_blocks([&](size_t b, int c, int t) {
          update_stress<NPP, Gradient::kUpdated>(sim, dt, b, c, t);
        });
      });
    }
    store_max_speed(sim);
  }

  template <int NPP>
  void step_usf(Simulation<D>& sim, double dt) {
    // USF: stress from the velocity field at t^n, then forces, then the grid update.
    zero(node_, sim.threads);
    sim.scatter_blocks([&](size_t b, int c, int t) { scatter<NPP, true, false>(sim, b, c, t); });
    momentum_to_velocity(sim, node_.data(), S, 1);
    sim.gather_blocks(
        [&](size_t b, int c, int t) { update_stress<NPP, Gradient::kCurrent>(sim, dt, b, c, t); });
    sim.scatter_blocks([&](size_t b, int c, int t) { scatter<NPP, false, true>(sim, b, c, t); });
    integrate(sim, dt);
    reset_max_speed();
    sim.gather_blocks(
        [&](size_t b, int c, int t) { update_velocity<NPP, false, true>(sim, dt, b, c, t); });
    store_max_speed(sim);
  }
};

LOAM_REGISTER_DEFAULT(Scheme, SinglePhase)

}  // namespace loam
