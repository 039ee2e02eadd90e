// Saturated soil with one set of material points carrying both phases: the v-w formulation of
// the FEM-and-MPM comparison of large-strain consolidation (seed 001; its copy names no title or
// authors, docs/verification.md lists it), eqs. 11-17; Jassim, Stolle & Vermeer 2013; Zabala &
// Alonso 2011.
//
// Per particle: solid velocity v (the `velocity` field), water velocity w, porosity n, excess
// pore pressure p (COMPRESSION POSITIVE, Pa), effective stress sigma' (the material's `stress`,
// tension positive). Total stress sigma = sigma' - p I. The particle `mass` is the solid mass
// (1 - n0) rho_s V0 (the material's density is the grain density rho_s); the water mass
// n rho_w V follows the current porosity and volume.
//
// Per step (lumped masses, explicit in the forces; stress after the grid update):
//   1. particle -> grid: solid mass and momentum, water mass and momentum, and per node
//        mixture force  F   = sum [ -V (sigma' - p I) grad N + (m_s + m_w) g N + f_ext N ]
//        water force    F_w = n_I sum [ V p grad N ] + m_w g N        (-n grad p, weak form;
//                         n_I the nodal porosity. sum [V n p grad N] would be -grad(n p), a
//                         spurious -p grad n where the porosity varies: it drove the large-
//                         strain column unstable without pressure smoothing)
//        drag           Q_I = sum V Q_p N     (Q from the drag plugin, per unit mixture volume:
//                                              force on the water -Q (w - v))
//   2. grid: loads, the face forces of boundary conditions (a prescribed pore pressure) and
//      local damping (on the mixture force, see damp_mixture) come in, then the water momentum
//      m_w dw/dt = F_w - Q (w - v) and the mixture momentum m_s dv/dt + m_w dw/dt = F are
//      solved with the drag IMPLICIT node by node: per node and component
//        (m_w/dt + Q) w' - Q v'           = m_w w/dt + F_w
//        -Q w'          + (m_s/dt + Q) v' = m_s v/dt + F - F_w
//      (a 2x2 solve, unconditionally stable in Q, so low permeability does not shrink the time
//      step). Boundary conditions act on both phases (a fixed or slip face is impermeable: the
//      water cannot cross it either); a face without a condition is free and drained (p = 0
//      is the natural condition of the water equation). They receive both phases of the update
//      at once, with the nodal solid and water masses (Boundary::constrain_grid_update), so a
//      condition may couple the phases or apply implicit forces (e.g. absorbing dashpots). A
//      phase left free where its partner was held (fixed + drained) is then solved again
//      against the held velocity (follow_held_phase).
//   3. grid -> particle: FLIP/PIC update of v and w from the grid accelerations, or with
//      `transfer: apic` the affine transfer of both phases (each particle carries B_p of v and of
//      w, fields affine_moment and water_affine_moment; framework/affine_transfer.hpp), whose
//      P2G in step 1 then scatters the affine momenta. `update: musl`
//      (default) re-maps the new particle momenta of both phases to the grid (Sulsky 1995)
//      with the particles still at x^n, takes the gradients below from those velocities on the
//      same stencil, then moves the particles with the solid grid velocity; `update: usl` takes
//      the gradients from the updated grid velocities directly (nearly empty nodes, e.g. at a
//      moving drained surface, then give spurious gradients).
//   4. particle update: L_s = grad v, L_w = grad w;
//      V <- det(I + L_s dt) V, F <- (I + L_s dt) F when requested; solid volume (1 - n) V is
//      conserved, so n <- 1 - (1 - n)/J; p <- p - dt K_w/n [ (1 - n) tr L_s + n tr L_w ] (storage
//      equation, eq. 15) and the material updates sigma' with L_s (Jaumann rate), one call per
//      block.
//   5. pressure_smoothing: cell (default): the pore pressure is projected per grid cell onto
//      the pressure space stable with the shape function (framework/cell_projection.hpp): the
//      cell's volume-weighted mean (linear, gimp, cpdi) or its linear fit (bspline2); see
//      apply_pressure_increment: without it the pressure checkerboards once particles cross
//      cells.
// Time step: the CFL limit with the fastest wave of the drag-free two-phase equations (the
// largest eigenvalue of the phases' 2x2 stiffness-mass problem, fast_wave_speed2) and the water
// wave speed sqrt(K_w/rho_w); no drag limit (implicit drag).
// Energies (history.csv) include the water's kinetic and gravity energy and the pore water's
// compression energy p^2 n V / (2 K_w) (add_energies).
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>

#include "framework/affine_transfer.hpp"
#include "framework/cell_projection.hpp"
#include "framework/drag.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/step_blocks.hpp"
#include "framework/tensor.hpp"
#include "framework/two_phase_blocks.hpp"

namespace loam {

template <int D>
class TwoPhaseSinglePoint : public Scheme<D> {
 public:
  static constexpr const char* name = "two_phase_single_point";
  static constexpr const char* summary =
      "saturated soil, one point per volume carrying solid and water (v-w formulation, "
      "docs/verification.md C), implicit nodal drag";
  static Schema schema() {
    Schema s;
    s.plugin("drag", "drag", "drag law between water and skeleton (darcy, ergun)").required();
    s.real("porosity", "-", "initial porosity n0 of every body (0 < n0 < 1)")
        .required()
        .above(0)
        .below(1);
    s.real("water_bulk_modulus", "Pa", "bulk modulus K_w of the pore water (2.2e9 for water)")
        .def("2.2e9")
        .positive();
    s.choice("update", {"musl", "usl"},
             "musl: velocity gradients from the re-mapped particle momenta of both phases "
             "(robust where nodes are nearly empty, e.g. a moving drained surface); usl: from "
             "the updated grid velocities directly (one pass less)")
        .def("musl");
    s.choice("pressure_smoothing", {"cell", "none"},
             "cell: after every step the pore pressure is projected per grid cell onto the "
             "pressure space stable with the shape function: the cell's volume-weighted mean "
             "(linear, gimp, cpdi) or its volume-weighted linear fit (bspline2, whose "
             "gradients vary inside a cell); removes the particle-to-particle pressure "
             "checkerboard that appears once particles cross cells; none: every particle keeps "
             "its own pressure")
        .def("cell");
    add_transfer_params(s, "; gimp, bspline2 or cpdi");
    return s;
  }
  explicit TwoPhaseSinglePoint(const Params& p)
      : drag_(Registry::instance().create<Drag, D>(p.section("drag"))),
        n0_(p.real("porosity")),
        Kw_(p.real("water_bulk_modulus")),
        flip_(p.real("flip")),
        update_(p.text("update") == "musl" ? UpdateOrder::kMusl : UpdateOrder::kUsl),
        transfer_(p.text("transfer")),
        affine_on_(AffineTransfer<D>::is_affine(transfer_)),
        transfer_where_(p.where("transfer")),
        transfer_path_(p.path("transfer")),
        smooth_(p.text("pressure_smoothing") == "cell") {}

  int phases() const override { return 2; }
  std::vector<std::string> velocity_fields() const override {
    if (affine_on_) return {"water_velocity", "affine_moment", "water_affine_moment"};
    return {"water_velocity"};
  }
  std::vector<SetDeclaration> particle_sets() const override {
    return {{"particles", "points of the saturated mixture: the skeleton carrying its pore water"}};
  }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    w_ = sim.request_field(
        {"water_velocity", D, "m/s", "pore water velocity", Particles<D>::axis_names()});
    n_ = sim.request_field({"porosity", 1, "-", "porosity (pore volume / total volume)", {}});
    p_ = sim.request_field(
        {"pore_pressure", 1, "Pa", "excess pore water pressure, compression positive", {}});
    // One set, the mixture's points (the default declaration): the per-particle scratch below
    // (dp_, move_, the cell projection) is indexed by its particles.
    auto& P = sim.sets[0].particles;
    rho_w_ = drag_->water_density();
    initialize_particles(sim, sim.sets[0], 0, P.size());
    drag_->setup(sim, diag);
    node_.assign(sim.grid.num_nodes * S, 0.0);
    solved_.assign(sim.grid.num_nodes * 2 * D, 0.0);
    dp_.assign(P.size(), 0.0);
    if (update_ == UpdateOrder::kMusl) remap_.assign(sim.grid.num_nodes * 2 * D, 0.0);
    scratch_ = make_block_scratch<Scratch>(sim.threads, sim.shape->max_nodes_per_particle(),
                                           [](Scratch& s) { s.Q.assign(size_t(kBlock), 0.0); });
    if (affine_on_) setup_apic(sim, diag);
  }

  /// transfer: apic or tpic: B_p (C_p) fields of both phases. Linear tents need USF's gradient
  /// (see framework/affine_transfer.hpp), which this scheme does not have: refused.
  void setup_apic(Simulation<D>& sim, Diagnostics& diag) {
    affine_.setup(sim.grid, *sim.shape, transfer_ == "tpic");
    Bs_ = sim.request_field(affine_.field_info("affine_moment", "solid velocity"));
    Bw_ = sim.request_field(affine_.field_info("water_affine_moment", "water velocity"));
    refuse_affine_shape(affine_, *sim.shape, transfer_, transfer_where_, transfer_path_, diag);
  }

  /// Porosity n0, solid mass (1 - n0) rho_s V (the material density is rho_s), water velocity
  /// equal to the skeleton's.
  void initialize_particles(Simulation<D>&, ParticleSet<D>& set, size_t b, size_t e) override {
    auto& P = set.particles;
    for (size_t i = b; i < e; ++i) {
      P.col(n_)[i] = n0_;
      P.col(P.mass)[i] *= 1 - n0_;
      for (int d = 0; d < D; ++d) P.col(w_, d)[i] = P.col(P.velocity, d)[i];
    }
  }

  double stable_dt(const Simulation<D>& sim) const override {
    // A water-only region: the water wave; the mixture: the fast wave of the drag-free phases.
    const double c2 =
        std::max(Kw_ / rho_w_, max_fast_wave_speed2(sim, sim.sets[0], n_, Kw_, rho_w_));
    return sim.cfl * sim.grid.min_cell() / (std::sqrt(c2) + sim.max_speed);
  }

  /// The pore water's share of the energies: kinetic 1/2 m_w |w|^2 and momentum m_w w with
  /// m_w = n rho_w V, its weight -m_w g . x, and its stored compression energy p^2 n V / (2 K_w)
  /// (p the excess pore pressure, Delta p = -K_w/n Delta(volumetric storage), eq. 15).
  void add_energies(const Simulation<D>& sim, Energies& e) const override {
    const auto& P = sim.sets[0].particles;
    const double* V = P.col(P.volume);
    const double* n = P.col(n_);
    const double* p = P.col(p_);
    for (size_t i = 0; i < P.size(); ++i) {
      const double mw = n[i] * rho_w_ * V[i];
      for (int d = 0; d < D; ++d) {
        const double w = P.col(w_, d)[i];
        e.kinetic += 0.5 * mw * w * w;
        e.momentum[size_t(d)] += mw * w;
        e.gravity -= mw * sim.gravity[size_t(d)] * P.col(P.position, d)[i];
      }
      e.strain += p[i] * p[i] * n[i] * V[i] / (2 * Kw_);
    }
  }

  /// Both nodal records completed over the ranks after their scatters, and the cell sums of the
  /// pressure smoothing after the move.
  bool runs_on_ranks() const override { return true; }

  std::vector<GridFieldView> grid_fields() const override {
    return {{"mass", 1, node_.data(), S, 0},
            {"velocity", D, node_.data(), S, kV},
            {"water_velocity", D, node_.data(), S, kW}};
  }

  void step(Simulation<D>& sim, double dt) override {
    F_ = sim.deformation_gradient;  // may be requested after our set-up
    // Per-particle scratch follows the particle count (sources and sinks change it).
    dp_.resize(sim.sets[0].size());
    if (update_ == UpdateOrder::kMusl) move_.resize(sim.sets[0].size() * D);
    with_stencil_size<D>(sim.shape->nodes_per_particle(),
                         [&](auto npp) { step_phases<decltype(npp)::value>(sim, dt); });
  }

 private:
  template <int NPP>
  void step_phases(Simulation<D>& sim, double dt) {
    sim.timed("grid", [&] { zero_nodes(node_, sim.threads); });
    sim.timed("p2g", [&] {
      sim.scatter_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
        with_form<NPP>(sim, s, b, c, t, affine_on_,
                       [&](auto form) { scatter<NPP, decltype(form)::value>(sim, s, b, c, t); });
      });
    });
    sim.complete_nodes({{node_.data(), S, S}});
    sim.timed("grid", [&] { integrate(sim, dt); });
    reset_max_speed(scratch_);
    if (update_ == UpdateOrder::kMusl) {
      sim.timed("grid", [&] { zero_nodes(remap_, sim.threads); });
      sim.timed("g2p_velocity_remap", [&] {
        sim.scatter_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
          with_form<NPP>(sim, s, b, c, t, affine_on_, [&](auto form) {
            remap<NPP, decltype(form)::value>(sim, s, dt, b, c, t);
          });
        });
      });
      sim.complete_nodes({{remap_.data(), 2 * D, 2 * D}});
      sim.timed("grid", [&] {
        remapped_two_phase_velocities(sim, node_.data(), kRecord, remap_,
                                      MasslessWater::kFollowsSolid);
      });
    }
    sim.timed("g2p_gradient_stress", [&] {
      sim.gather_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
        // USL takes B_p here (the stencil with the affine geometry), MUSL took it in the re-map.
        with_form<NPP>(sim, s, b, c, t, affine_on_ && update_ != UpdateOrder::kMusl,
                       [&](auto form) {
                         constexpr AffineForm F = decltype(form)::value;
                         if constexpr (F == AffineForm::kOff)
                           if (update_ == UpdateOrder::kMusl)
                             return update<NPP, UpdateOrder::kMusl, F>(sim, s, dt, b, c, t);
                         update<NPP, UpdateOrder::kUsl, F>(sim, s, dt, b, c, t);
                       });
      });
    });
    sim.timed("pore_pressure", [&] { apply_pressure_increment(sim); });
    sim.max_speed = max_speed(scratch_);
    report_bad_porosity(sim);
  }

  /// A particle whose porosity left (0, 1) in the step ends the run (Simulation::failure).
  void report_bad_porosity(Simulation<D>& sim) {
    for (auto& s : scratch_)
      if (s->bad_porosity >= 0) {
        const size_t i = size_t(s->bad_porosity);
        const auto& P = sim.sets[0].particles;
        sim.failure = "particle " + std::to_string(P.id[i]) +
                      ": porosity left (0, 1) (n = " + format_number(P.col(n_)[i]) +
                      "); the skeleton was compressed to zero pore volume or torn apart";
        s->bad_porosity = -1;
      }
  }

  // Node record: solid mass, water mass, solid momentum -> velocity, water momentum ->
  // velocity, mixture force -> solid acceleration, water force -> water acceleration, drag Q,
  // volume -> porosity.
  static constexpr int kMs = 0, kMw = 1, kV = 2, kW = 2 + D, kF = 2 + 2 * D, kFw = 2 + 3 * D,
                       kQ = 2 + 4 * D, kN = 3 + 4 * D, S = 4 + 4 * D;
  static constexpr TwoPhaseRecord kRecord{kMs, kMw, kQ, kV, kW, kF, kFw, kN, S};
  static constexpr int NS = Particles<D>::NS;
  std::unique_ptr<Drag<D>> drag_;
  double n0_, Kw_, flip_, rho_w_ = 1000;
  UpdateOrder update_;       // usl or musl
  std::string transfer_;     // flip, apic or tpic
  bool affine_on_;           // an affine transfer (apic or tpic)
  Location transfer_where_;  // for set-up errors about `transfer`
  std::string transfer_path_;
  int Bs_ = -1, Bw_ = -1;     // APIC: B_p of the solid and the water velocity, or -1
  AffineTransfer<D> affine_;  // APIC's per-entry algebra
  using AffineStencil = typename AffineTransfer<D>::Stencil;
  std::vector<double> remap_;  // MUSL: per node solid then water velocity (2 D values)
  int w_ = -1, n_ = -1, p_ = -1, F_ = -1;
  std::vector<double> node_;
  std::vector<double> solved_;  // per node: v', w' of the coupled solve (2 D values)
  std::vector<double> move_;    // MUSL: per particle, dt v_grid from the re-map pass (D values)
  std::vector<double> mixture_momentum_;  // per node (D values), once damping is on
  std::vector<double> water_force_;       // per node (D values), once the water is damped
  // Pore-pressure increments of the step and, per grid cell, the volume-weighted sum of the
  // updated pressures and the volume (pressure_smoothing: cell).
  std::vector<double> dp_;
  CellProjection<D> cells_;  // the pore pressure per cell (pressure_smoothing: cell)
  bool smooth_ = true;
  struct Scratch : BlockScratch<D> {
    std::vector<double> Q;   // drag coefficients of the block
    long bad_porosity = -1;  // a particle whose porosity left (0, 1) this step
  };
  std::vector<std::unique_ptr<Scratch>> scratch_;

  /// Add the storage-equation increments dp_ to the particles' pore pressure and, with
  /// pressure_smoothing: cell, project it per grid cell onto the shape function's pressure
  /// space (the volume-weighted mean, or the linear fit for B-splines). Without it the pressure
  /// field has one degree of freedom per particle against one velocity per node: a pressure
  /// alternating from particle to particle exerts (nearly) no nodal force, so nothing restrains it,
  /// and once particles cross cells the storage equation feeds it (the soft column of
  /// configs/seed001_large_strain.yaml: +-2 MPa under a 50 kPa load, then a porosity outside
  /// the range 0 to 1). One pressure per cell is the constant-pressure (Q1-P0) element of mixed
  /// finite elements and the element-wise liquid-pressure smoothing of the Anura3D v-w code; it
  /// conserves the volume integral of p in each cell. With B-splines it is not in equilibrium with
  /// the weight where a free surface cuts their support (framework/cell_projection.hpp). Averaging
  /// only the increments is not enough: the checkerboard left by particles that change cells stays
  /// frozen
  /// (+-9 kPa).
  void apply_pressure_increment(Simulation<D>& sim) {
    Particles<D>& P = sim.sets[0].particles;
    const long np = long(P.size());
    double* p = P.col(p_);
    if (!smooth_) {
#pragma omp parallel for schedule(static) num_threads(sim.threads)
      for (long i = 0; i < np; ++i) p[i] += dp_[size_t(i)];
      return;
    }
    const double* V = P.col(P.volume);
    cells_.fit(sim, P, sim.shape->cell_pressure(), [&](size_t i, double& w, double& wf) {
      w = V[i];
      wf = V[i] * (p[i] + dp_[i]);
    });
#pragma omp parallel for schedule(static) num_threads(sim.threads)
    for (long i = 0; i < np; ++i) p[i] = cells_.at(sim.grid, P, size_t(i));
  }

  /// Block b's stencil evaluated (with the affine geometry when `affine`) and kernel(form)
  /// called with its AffineForm: each pass's loop is compiled per form.
  template <int NPP, class Kernel>
  void with_form(Simulation<D>& sim, ParticleSet<D>& s, size_t b, int count, int thread,
                 bool affine, Kernel&& kernel) {
    affine_.template evaluate_with_form<NPP>(sim, s.particles, b, count,
                                             scratch_[size_t(thread)]->stencil, affine, kernel);
  }

  /// APIC: both phases' B_p columns (AffineTransfer::Columns), looked up once per block.
  struct AffineColumns {
    typename AffineTransfer<D>::Columns s, w;
  };
  AffineColumns affine_columns(Particles<D>& P) const {
    return {AffineTransfer<D>::columns(P, Bs_), AffineTransfer<D>::columns(P, Bw_)};
  }

  /// APIC: the affine momenta per unit weight of both phases of particle i (solid mass ms,
  /// water mass mw) for each of its npp stencil entries, at the stencil geometry `as`.
  template <int NPP, AffineForm FORM>
  using Momenta = typename AffineTransfer<D>::template Momenta<NPP, FORM>;
  template <int NPP, AffineForm FORM>
  void affine_momenta(const AffineColumns& B, const double (&vs)[D], const double (&vw)[D],
                      size_t i, int npp, double ms, double mw, const AffineStencil& as,
                      Momenta<NPP, FORM>& am_s, Momenta<NPP, FORM>& am_w) const {
    double msv[D], mwv[D], mCs[D][D], mCw[D][D];
    for (int d = 0; d < D; ++d) {
      msv[d] = ms * vs[d];
      mwv[d] = mw * vw[d];
    }
    affine_.matrix(B.s, i, ms, as, mCs);
    affine_.matrix(B.w, i, mw, as, mCw);
    AffineTransfer<D>::template momenta<NPP>(as, npp, msv, mCs, am_s);
    AffineTransfer<D>::template momenta<NPP>(as, npp, mwv, mCw, am_w);
  }

  /// P2G of one evaluated block: both phases' masses and momenta (with an affine FORM, APIC's),
  /// the drag coefficient, the volume and the mixture's and the water's forces.
  template <int NPP, AffineForm FORM>
  void scatter(Simulation<D>& sim, ParticleSet<D>& set, size_t b, int count, int thread) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    const StencilBlock<D>& st = sc.stencil;
    const int npp = NPP ? NPP : st.npp;
    const double* ms = P.col(P.mass) + b;
    const double* V = P.col(P.volume) + b;
    const double* n = P.col(n_) + b;
    const double* pw = P.col(p_) + b;
    std::array<const double*, D> v{}, vw{}, fe{};
    std::array<const double*, NS> sig{};
    for (int d = 0; d < D; ++d) {
      v[size_t(d)] = P.col(P.velocity, d) + b;
      vw[size_t(d)] = P.col(w_, d) + b;
      fe[size_t(d)] = sim.external_force >= 0 ? P.col(sim.external_force, d) + b : nullptr;
    }
    for (int c = 0; c < NS; ++c) sig[size_t(c)] = P.col(P.stress, c) + b;
    // Drag coefficients of the block (relative speeds only for speed-dependent laws).
    double speed[kBlock];
    if (drag_->speed_dependent())
      for (int p = 0; p < count; ++p) {
        double s2 = 0;
        for (int d = 0; d < D; ++d) {
          const double r = vw[size_t(d)][p] - v[size_t(d)][p];
          s2 += r * r;
        }
        speed[p] = std::sqrt(s2);
      }
    drag_->coefficient(size_t(count), n, drag_->speed_dependent() ? speed : nullptr, sc.Q.data());
    double* g = node_.data();
    const std::array<double, D> gravity = sim.gravity;
    AffineStencil as;
    Momenta<NPP, FORM> am_s, am_w;  // APIC: the phases' momenta per unit weight
    AffineColumns B;
    if constexpr (AFFINE) B = affine_columns(P);
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      const double mw = n[p] * rho_w_ * V[p];
      double vs[D], vwp[D], body[D], sv[D][D];
      for (int d = 0; d < D; ++d) {
        vs[d] = v[size_t(d)][p];
        vwp[d] = vw[size_t(d)][p];
        body[d] = (ms[p] + mw) * gravity[size_t(d)] + (fe[size_t(d)] ? fe[size_t(d)][p] : 0.0);
        for (int j = 0; j < D; ++j)
          sv[d][j] = V[p] * (sig[size_t(voigt_index(d, j))][p] - (d == j ? pw[p] : 0.0));
      }
      if constexpr (AFFINE) {
        affine_.stencil(P, st, p, i, npp, as);
        affine_momenta<NPP>(B, vs, vwp, i, npp, ms[p], mw, as, am_s, am_w);
      }
      const double vp = V[p] * pw[p], vq = V[p] * sc.Q[size_t(p)];
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            const double w = st.w[kp];
            double* r = g + size_t(st.node[kp]) * S;
            r[kMs] += w * ms[p];
            r[kMw] += w * mw;
            r[kQ] += w * vq;
            r[kN] += w * V[p];  // volume; the nodal porosity m_w / (rho_w V_I) in integrate()
            double gr[D];
            for (int j = 0; j < D; ++j)
              gr[j] = st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
            for (int d = 0; d < D; ++d) {
              if constexpr (AFFINE) {  // the phases' affine momenta
                r[kV + d] += w * am_s.at(k, d);
                r[kW + d] += w * am_w.at(k, d);
              } else {
                r[kV + d] += w * ms[p] * vs[d];
                r[kW + d] += w * mw * vwp[d];
              }
              double f = w * body[d];
              for (int j = 0; j < D; ++j) f -= sv[d][j] * gr[j];
              r[kF + d] += f;
              r[kFw + d] += vp * gr[d];  // the water's weight is added per node
            }
          });
    }
  }

  /// Nodal velocities and accelerations of both phases, drag implicit (see the header), as named
  /// phases: forces of the mixture and the water, the coupled solve, the boundary conditions,
  /// and the drag re-solve of a phase whose partner a condition has held.
  void integrate(Simulation<D>& sim, double dt) {
    sim.apply_grid_loads(NodalVector{node_.data(), S, kF});
    water_force_and_porosity(sim);
    GridForces f;
    f.mixture = NodalVector{node_.data(), S, kF};
    f.water = NodalVector{node_.data(), S, kFw};
    f.porosity = NodalVector{node_.data(), S, kN};
    f.count = 2;
    sim.apply_boundary_forces(f);
    damp_mixture(sim);
    solve_two_phase_nodes<D, PhaseNodes::kMixture>(sim, node_.data(), kRecord, solved_.data(), dt);
    constrain_two_phase_update<D>(sim, node_.data(), kRecord, solved_.data(), dt);
  }

  /// Per node: the porosity n_I = m_w / (rho_w V_I) and the water force
  ///   F_w = n_I sum [ V p grad N ] + m_w g
  /// (-n grad p: the nodal porosity times the weak form of -grad p, not of -grad(n p), which
  /// would add a spurious -p grad n where n varies).
  void water_force_and_porosity(Simulation<D>& sim) {
    const double tol = sim.mass_tolerance;
    for_each_record(sim, [&](double* r, size_t) {
      if (r[kMs] <= tol) {
        r[kN] = 0.0;
        return;
      }
      r[kN] = r[kN] > 0 ? r[kMw] / (rho_w_ * r[kN]) : 0.0;
      for (int d = 0; d < D; ++d) r[kFw + d] = r[kN] * r[kFw + d] + r[kMw] * sim.gravity[size_t(d)];
    });
  }

  /// f(record, node) for every grid node, in parallel (static schedule).
  template <class F>
  void for_each_record(const Simulation<D>& sim, F&& f) {
    double* g = node_.data();
    for_each_node(sim.grid.num_nodes, sim.threads, [&](size_t i) { f(g + i * S, i); });
  }

  /// Local damping (damping:) acts on the mixture's momentum balance: the net nodal force of
  /// the mixture against the mixture momentum m_s v + m_w w. The water's balance relative to
  /// the skeleton is left to the drag, which dissipates already: damping the water force itself
  /// would slow steady seepage (where the water force balances the drag, not zero) by (1 - alpha).
  void damp_mixture(Simulation<D>& sim) {
    if (!sim.damping) return;
    mixture_momentum_.resize(sim.grid.num_nodes * D);  // damping may start with a later stage
    for_each_record(sim, [&](const double* r, size_t i) {
      for (int d = 0; d < D; ++d) mixture_momentum_[i * D + size_t(d)] = r[kV + d] + r[kW + d];
    });
    sim.apply_damping(NodeForces{node_.data() + kMs, NodalVector{mixture_momentum_.data(), D, 0},
                                 NodalVector{node_.data(), S, kF}, sim.grid.num_nodes, S});
    if (sim.damping->phases() == DampedPhases::solid_and_liquid) damp_water(sim);
  }
  /// With `liquid: true` the water's own balance too (a settle stage): its force F_w against
  /// its momentum m_w w; the mixture's force F takes the same change, so the skeleton's
  /// F - F_w keeps its own.
  void damp_water(Simulation<D>& sim) {
    water_force_.resize(sim.grid.num_nodes * D);
    for_each_record(sim, [&](const double* r, size_t i) {
      for (int d = 0; d < D; ++d) water_force_[i * D + size_t(d)] = r[kFw + d];
    });
    sim.apply_damping(NodeForces{node_.data() + kMw, NodalVector{node_.data(), S, kW},
                                 NodalVector{node_.data(), S, kFw}, sim.grid.num_nodes, S},
                      nullptr, MomentumBalance::kLiquid);
    for_each_record(sim, [&](double* r, size_t i) {
      for (int d = 0; d < D; ++d) r[kF + d] += r[kFw + d] - water_force_[i * D + size_t(d)];
    });
  }

  /// MUSL first pass: FLIP/PIC update of both particle velocities and the scatter of their new
  /// momenta to the grid. The particles stay at x^n: the gradient pass takes L on the same
  /// start-of-step stencil and moves them after it (Sulsky 1995; as single_phase does). Moving
  /// here would make the gradient pass evaluate the stencil at x^{n+1} against velocities
  /// re-mapped with the weights at x^n, so that a node without mass at x^n contributes zero
  /// velocity: a rigidly translating block then showed |p| up to 7.9e5 Pa.
  template <int NPP, AffineForm FORM>
  void remap(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count, int thread) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    const StencilBlock<D>& st = sc.stencil;
    const int npp = NPP ? NPP : st.npp;
    double max_v2 = sc.max_v2, loss = 0;
    AffineStencil as;
    Momenta<NPP, FORM> am_s, am_w;  // APIC: the phases' momenta per unit weight
    AffineColumns B;
    if constexpr (AFFINE) B = affine_columns(P);
    const double* m = P.col(P.mass);
    const double* V = P.col(P.volume);
    const double* n = P.col(n_);
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      double vs[D], vw[D];
      max_v2 =
          std::max(max_v2, velocity_update<NPP, VelocityPass::kRemap, FORM>(
                               sim, P, st, p, i, npp, dt, &move_[i * D], vs, vw, &as, B, loss));
      const double ms = m[i], mw = n[i] * rho_w_ * V[i];
      // The re-map carries the affine momenta, with D_p at x^n (as the scatter).
      if constexpr (AFFINE) affine_momenta<NPP>(B, vs, vw, i, npp, ms, mw, as, am_s, am_w);
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            double* r = remap_.data() + size_t(st.node[kp]) * 2 * D;
            for (int d = 0; d < D; ++d) {
              if constexpr (AFFINE) {
                r[d] += st.w[kp] * am_s.at(k, d);
                r[D + d] += st.w[kp] * am_w.at(k, d);
              } else {
                r[d] += st.w[kp] * ms * vs[d];
                r[D + d] += st.w[kp] * mw * vw[d];
              }
            }
          });
    }
    sc.max_v2 = max_v2;
    if (flip_ < 1) sim.ledger.add_transfer_loss(sim.set_slot(set), b, 0.5 * loss);
  }

  /// Particle p (index i) of a block: FLIP/PIC update of v and w from the grid record and its
  /// move dt v_grid with the solid grid velocity: done now with kUpdateAndMove (kept inside the
  /// held faces), else stored in `move` (D values) for the gradient pass; the new velocities also
  /// in vs, vw; returns |v|^2. With an affine FORM: v and w from the grid velocities and both B_p
  /// (into the columns B), taken at x^n before the move (framework/affine_transfer.hpp), `as`
  /// left holding the stencil geometry there.
  template <int NPP, VelocityPass PASS, AffineForm FORM>
  double velocity_update(const Simulation<D>& sim, Particles<D>& P, const StencilBlock<D>& st,
                         int p, size_t i, int npp, double dt, double* move, double (&vs)[D],
                         double (&vw)[D], AffineStencil* as, const AffineColumns& B, double& loss) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    double vn[D] = {}, wn[D] = {}, acc_s[D] = {}, acc_w[D] = {};
    typename AffineTransfer<D>::template MomentSum<NPP, FORM> sum_s, sum_w;  // both phases' B_p
    if constexpr (AFFINE) {
      sum_s.clear();
      sum_w.clear();
      affine_.stencil(P, st, p, i, npp, *as);
    }
    for_each_entry<FORM>(
        npp, [&](int k) __attribute__((always_inline)) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          const double w = st.w[kp];
          const double* r = node_.data() + size_t(st.node[kp]) * S;
          for (int d = 0; d < D; ++d) {
            vn[d] += w * r[kV + d];
            wn[d] += w * r[kW + d];
            if constexpr (!AFFINE) {
              acc_s[d] += w * r[kF + d];
              acc_w[d] += w * r[kFw + d];
            }
          }
          if constexpr (AFFINE) {
            affine_.add_moment(sum_s, st, k, p, w, r + kV, *as);
            affine_.add_moment(sum_w, st, k, p, w, r + kW, *as);
          }
        });
    if constexpr (AFFINE) {
      double Bs[D][D], Bw[D][D];
      affine_.moment(sum_s, *as, Bs);
      affine_.moment(sum_w, *as, Bw);
      B.s.store(i, Bs);
      B.w.store(i, Bw);
    }
    double v2 = 0;
    for (int d = 0; d < D; ++d) {
      double& v = P.col(P.velocity, d)[i];
      double& w = P.col(w_, d)[i];
      if constexpr (AFFINE) {
        v = vn[d];
        w = wn[d];
      } else {
        const double v_old = v, w_old = w;
        v = flip_pic(flip_, v, dt, acc_s[d], vn[d]);
        w = flip_pic(flip_, w, dt, acc_w[d], wn[d]);
        if (flip_ < 1)
          loss +=
              P.col(P.mass)[i] * transfer_loss(v_old, dt, acc_s[d], v) +
              P.col(n_)[i] * rho_w_ * P.col(P.volume)[i] * transfer_loss(w_old, dt, acc_w[d], w);
      }
      vs[d] = v;
      vw[d] = w;
      if constexpr (moves(PASS))
        P.col(P.position, d)[i] = sim.held_faces.moved(d, P.col(P.position, d)[i], dt * vn[d]);
      else
        move[d] = dt * vn[d];
      v2 += v * v;
    }
    return v2;
  }

  /// The gradient pass of one evaluated block (USL: with the velocity update, affine FORM as
  /// velocity_update; MUSL: FORM kOff, B_p was taken in the re-map): L of both phases, the
  /// move, volume, F, porosity and the storage equation, then the stress update.
  template <int NPP, UpdateOrder ORDER, AffineForm FORM>
  void update(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count, int thread) {
    constexpr bool REMAPPED = ORDER == UpdateOrder::kMusl;
    static_assert(!REMAPPED || FORM == AffineForm::kOff, "MUSL takes B_p in the re-map");
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    const StencilBlock<D>& st = sc.stencil;
    const int npp = NPP ? NPP : st.npp;
    AffineColumns B;
    if constexpr (FORM != AffineForm::kOff) B = affine_columns(P);
    const double* g = node_.data();
    double* L = sc.L.data();
    double max_v2 = sc.max_v2, loss = 0;
    const auto F = deformation_gradient_block(P, F_, b);
    AffineStencil as;
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      // USL: the velocity update happens here; MUSL did it in the re-map pass.
      // (the stencil was evaluated at x^n above, so moving here does not change it).
      if constexpr (!REMAPPED) {
        double vs[D], vw[D];
        max_v2 = std::max(max_v2, velocity_update<NPP, VelocityPass::kUpdateAndMove, FORM>(
                                      sim, P, st, p, i, npp, dt, nullptr, vs, vw, &as, B, loss));
      }
      double ls[D][D] = {}, lw[D][D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const double* r = g + size_t(st.node[kp]) * S;
        // Velocities whose gradients are taken: re-mapped (MUSL) or updated grid ones (USL).
        const double* vs = REMAPPED ? remap_.data() + size_t(st.node[kp]) * 2 * D : r + kV;
        const double* vw = REMAPPED ? vs + D : r + kW;
        add_velocity_gradient<D>(ls, vs, st, size_t(k), p);
        add_velocity_gradient<D>(lw, vw, st, size_t(k), p);
      }
      // MUSL: move with the updated solid grid velocity, after L on the start-of-step stencil;
      // no particle crosses a held face.
      if constexpr (REMAPPED)
        for (int d = 0; d < D; ++d)
          P.col(P.position, d)[i] =
              sim.held_faces.moved(d, P.col(P.position, d)[i], move_[i * D + size_t(d)]);
      double trs = 0, trw = 0;
      for (int d = 0; d < D; ++d) {
        trs += ls[d][d];
        trw += lw[d][d];
      }
      store_velocity_gradient<D>(ls, L, p);
      // Volume, F, porosity (solid volume (1 - n) V conserved) and the storage equation.
      const double J = update_volume_and_deformation<D>(ls, dt, P.col(P.volume)[i], F, p);
      double& n = P.col(n_)[i];
      const double n_old = n;
      n = 1 - (1 - n) / J;
      dp_[i] = -dt * Kw_ / n_old * ((1 - n_old) * trs + n_old * trw);
      if (!(n > 0 && n < 1)) sc.bad_porosity = long(i);
    }
    sc.max_v2 = max_v2;
    if (flip_ < 1) sim.ledger.add_transfer_loss(sim.set_slot(set), b, 0.5 * loss);
    sim.update_block_stress(set, b, count, dt, L);
  }
};

LOAM_REGISTER(Scheme, TwoPhaseSinglePoint)

}  // namespace loam
