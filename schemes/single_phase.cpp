// Single-phase explicit MPM (Sulsky et al. 1994; update variants after Bardenhagen 2002 and
// Nairn 2003): lumped mass, FLIP/PIC blend for the particle velocity, stress update before the
// force computation (USF), after the grid update (USL), or after re-mapping the updated particle
// momentum to the grid (MUSL, the default; least noisy for near-empty nodes).
//
// `transfer: apic` or `tpic`: the affine particle-in-cell transfers (APIC, Jiang et al. 2015;
// TPIC, Nakamura et al. 2023) with every update variant (framework/affine_transfer.hpp has the
// equations and why linear tents take them with update: usf only); the field affine_moment holds
// APIC's B_p, or C_p (TPIC, linear tents).
//
// With `contact:` each body in contact scatters onto a velocity field of its own and takes its
// velocity from it (framework/contact_fields.hpp); the loads, conditions and damping act on the
// fields' sum, the record every output sees.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "framework/affine_transfer.hpp"
#include "framework/contact_fields.hpp"
#include "framework/fbar.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/step_blocks.hpp"

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
    add_transfer_params(s, "; with linear tents update: usf");
    s.choice("volumetric", {"none", "fbar"},
             "volumetric locking treatment of the particles' stress: none (each particle's "
             "volume follows its own velocity gradient, det(I + L dt)) or fbar (F-bar: each "
             "particle takes the volume change projected onto the grid's nodes, the internal "
             "force the mean stress projected the same way; de Souza Neto et al. 1996, Hughes "
             "1980; docs/volumetric_locking.md)")
        .def("none");
    s.string_list("sets",
                  "names of the particle sets; all are summed onto the one velocity field (e.g. "
                  "a column split into two sets behaves as one), each has its own output frames")
        .def("[particles]");
    s.check([](const Params& p, Diagnostics& d) {
      const auto& names = p.strings("sets");
      if (names.empty()) d.error(p.where("sets"), p.path("sets"), "give at least one set");
      for (size_t i = 0; i < names.size(); ++i) {
        const bool plain =
            !names[i].empty() && std::all_of(names[i].begin(), names[i].end(), [](char c) {
              return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
            });
        if (!plain)
          d.error(p.where("sets", i), p.path("sets") + "." + std::to_string(i),
                  "a set name names its output files (<set>.xdmf): letters, digits, _ and - only");
        for (size_t j = 0; j < i; ++j)
          if (names[i] == names[j])
            d.error(p.where("sets", i), p.path("sets") + "." + std::to_string(i),
                    "duplicate set name '" + names[i] + "'");
      }
    });
    return s;
  }
  explicit SinglePhase(const Params& p)
      : params_(p),
        update_(p.text("update") == "usf"    ? UpdateOrder::kUsf
                : p.text("update") == "musl" ? UpdateOrder::kMusl
                                             : UpdateOrder::kUsl),
        flip_(p.real("flip")),
        transfer_(p.text("transfer")),
        affine_on_(AffineTransfer<D>::is_affine(transfer_)),
        sets_(p.strings("sets")),
        fbar_(volumetric_of(p)) {}

  /// The affine matrix is part of the particle velocity field (a velocity reset zeroes it).
  std::vector<std::string> velocity_fields() const override {
    return affine_on_ ? std::vector<std::string>{"affine_moment"} : std::vector<std::string>{};
  }

  std::vector<SetDeclaration> particle_sets() const override {
    std::vector<SetDeclaration> s;
    for (const auto& n : sets_) s.push_back({n, "material points on the one velocity field"});
    return s;
  }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    node_.assign(sim.grid.num_nodes * S, 0.0);
    if (sim.contact) {
      contact_.setup(sim, sim.config.section("contact"), diag);
      if (affine_on_)
        diag.error(params_.where("transfer"), params_.path("transfer"),
                   "contact between bodies takes transfer: flip (the affine moments of two "
                   "velocity fields are not implemented)");
      if (update_ == UpdateOrder::kUsl && !sim.shape->stencil_covers_domain())
        diag.error(params_.where("update"), params_.path("update"),
                   "contact with update: usl needs a shape function whose stencil covers the "
                   "particle's domain (gimp, cpdi, bspline2): with linear tents a node that one "
                   "body barely reaches takes its own f / m and the run blows up (a block on a "
                   "slab at 0.1 s); use musl or usf");
    }
    vel_.assign(sim.grid.num_nodes * D, 0.0);
    scratch_ = make_block_scratch<Scratch>(sim.threads, sim.shape->max_nodes_per_particle(),
                                           [](Scratch&) {});
    if (!affine_on_) return;
    affine_.setup(sim.grid, *sim.shape, transfer_ == "tpic");
    B_ = sim.request_field(affine_.field_info("affine_moment", "velocity"));
    if (affine_.needs_usf() && update_ != UpdateOrder::kUsf)
      diag.error(params_.where("transfer"), params_.path("transfer"),
                 "transfer: " + transfer_ +
                     " with linear tents needs update: usf (C_p is the velocity gradient of the "
                     "P2G field; with musl or usl the run loses its rotation or blows up: "
                     "framework/affine_transfer.hpp); or use gimp, bspline2 or cpdi");
    if (!AffineTransfer<D>::fits(*sim.shape))
      diag.error(params_.where("transfer"), params_.path("transfer"),
                 "transfer: " + transfer_ + " handles stencils of up to " +
                     std::to_string(AffineTransfer<D>::kMaxEntries) +
                     " nodes; this shape function uses " +
                     std::to_string(sim.shape->max_nodes_per_particle()));
  }

  /// Every nodal sum completed over the ranks after its scatter (Simulation::complete_nodes).
  bool runs_on_ranks() const override { return true; }
  bool supports_contact() const override { return true; }

  std::vector<GridFieldView> grid_fields() const override {
    return {{"mass", 1, node_.data(), S, kMass},
            {"velocity", D, vel_.data(), D, 0},
            {"acceleration", D, node_.data(), S, kForce}};
  }

  void step(Simulation<D>& sim, double dt) override {
    // Plugins may request F after this scheme's set-up; look it up once per step.
    F_ = sim.deformation_gradient;
    with_stencil_size<D>(sim.shape->nodes_per_particle(), [&](auto npp) {
      constexpr int NPP = decltype(npp)::value;
      auto with_fields = [&](auto fields) {
        constexpr Fields FIELDS = decltype(fields)::value;
        if (update_ == UpdateOrder::kUsf)
          step_usf<NPP, FIELDS>(sim, dt);
        else
          step_usl_musl<NPP, FIELDS>(sim, dt);
      };
      if (contact_.on())
        with_fields(std::integral_constant<Fields, Fields::kPerBody>{});
      else
        with_fields(std::integral_constant<Fields, Fields::kShared>{});
    });
  }

 private:
  // Node record for the scatter: mass, momentum (D), force (D). After the nodal update the
  // momentum slot holds the updated velocity and the force slot the acceleration.
  static constexpr int kMass = 0, kMomentum = 1, kForce = 1 + D, S = 1 + 2 * D;
  static constexpr int NS = Particles<D>::NS;
  Params params_;
  UpdateOrder update_;
  double flip_;
  std::string transfer_;      // flip, apic or tpic
  bool affine_on_;            // an affine transfer (apic or tpic)
  int B_ = -1;                // B_p or C_p (D x D, row-major; field affine_moment), or -1
  AffineTransfer<D> affine_;  // the affine per-entry algebra (framework/affine_transfer.hpp)
  std::vector<std::string> sets_;
  int F_ = -1;                // deformation gradient handle, or -1
  std::vector<double> node_;  // num_nodes * S
  std::vector<double> vel_;   // num_nodes * D: velocity used for the velocity gradient
  ContactFields<D> contact_;  // the bodies' own velocity fields, with `contact:`
  Fbar<D> fbar_;              // volumetric: fbar
  static_assert(ContactFields<D>::S == S && ContactFields<D>::kForce == kForce);
  static constexpr int G = ContactFields<D>::G;
  using Scratch = BlockScratch<D>;
  std::vector<std::unique_ptr<Scratch>> scratch_;

  NodalVector node_vector(int offset) { return NodalVector{node_.data(), S, offset}; }
  NodalVector vel_vector() { return NodalVector{vel_.data(), D, 0}; }

  // ------------------------------------------------------------------ the steps
  template <int NPP, Fields FIELDS>
  void step_usl_musl(Simulation<D>& sim, double dt) {
    sim.timed("grid", [&] { zero_records<FIELDS>(sim); });
    sim.timed("p2g", [&] { scatter_all<NPP, Scatter::kMomentumAndForce, FIELDS>(sim); });
    complete_records<FIELDS>(sim, kMass, S, true);
    sim.timed("grid", [&] { update_nodes<FIELDS>(sim, dt); });
    reset_max_speed(scratch_);
    if (update_ == UpdateOrder::kMusl) {
      // MUSL: re-map the updated particle momentum; the velocity gradient uses that field, and
      // particles move with the grid velocity of the update (Sulsky 1995).
      sim.timed("grid", [&] { zero_remap<FIELDS>(sim); });
      sim.timed("g2p_velocity_remap",
                [&] { update_velocities<NPP, VelocityPass::kRemap, FIELDS>(sim, dt); });
      sim.timed("grid", [&] { remapped_velocities<FIELDS>(sim); });
      sim.timed("g2p_gradient_stress",
                [&] { update_stresses<NPP, Gradient::kRemapped, FIELDS>(sim, dt); });
    } else {
      // USL: gradient, move and velocity update from the updated grid record in one pass (APIC:
      // its G2P first, at the positions before the move; the pass then only moves).
      if (affine_on_)
        sim.timed("g2p_velocity",
                  [&] { update_velocities<NPP, VelocityPass::kUpdate, FIELDS>(sim, dt); });
      sim.timed("g2p_gradient_stress",
                [&] { update_stresses<NPP, Gradient::kUpdated, FIELDS>(sim, dt); });
    }
    sim.max_speed = max_speed(scratch_);
  }

  template <int NPP, Fields FIELDS>
  void step_usf(Simulation<D>& sim, double dt) {
    // USF: stress from the velocity field at t^n, then forces, then the grid update.
    zero_records<FIELDS>(sim);
    scatter_all<NPP, Scatter::kMomentum, FIELDS>(sim);
    complete_records<FIELDS>(sim, kMass, 1 + D, true);
    momentum_to_velocity(sim, node_.data(), S, kMomentum);
    if constexpr (FIELDS == Fields::kPerBody)
      contact_.velocities_from_momenta(sim, ContactFields<D>::Momentum::kRecord);
    update_stresses<NPP, Gradient::kCurrent, FIELDS>(sim, dt);
    scatter_all<NPP, Scatter::kForce, FIELDS>(sim);
    complete_records<FIELDS>(sim, kForce, D, false);
    update_nodes<FIELDS>(sim, dt);
    reset_max_speed(scratch_);
    update_velocities<NPP, VelocityPass::kUpdateAndMove, FIELDS>(sim, dt);
    sim.max_speed = max_speed(scratch_);
  }

  // ------------------------------------------------------------------ the fields
  /// A new scatter: the shared record, and the bodies' fields with contact.
  template <Fields FIELDS>
  void zero_records(Simulation<D>& sim) {
    if constexpr (FIELDS == Fields::kPerBody) contact_.begin_step(sim);
    zero_nodes(node_, sim.threads);
  }
  /// The record slots [first, first + width) complete over the ranks; with contact the shared
  /// record is the fields' sum (their volumes too, `volumes`).
  template <Fields FIELDS>
  void complete_records(Simulation<D>& sim, int first, int width, bool volumes) {
    if constexpr (FIELDS == Fields::kShared) {
      sim.complete_nodes({{node_.data(), S, width, first}});
    } else {
      contact_.complete(sim, first, width, volumes);
      contact_.sum_into(node_.data(), first, width, sim.threads);
    }
  }
  template <Fields FIELDS>
  void zero_remap(Simulation<D>& sim) {
    if constexpr (FIELDS == Fields::kPerBody)
      contact_.zero_velocities(sim.threads);  // vel_ is their sum (remapped_velocities)
    else
      zero_nodes(vel_, sim.threads);
  }
  /// The re-mapped momenta to velocities (MUSL): the shared field's, and with contact each
  /// body's with the contact exchange.
  template <Fields FIELDS>
  void remapped_velocities(Simulation<D>& sim) {
    if constexpr (FIELDS == Fields::kPerBody) {
      // The shared field's too: the grid output's velocity.
      contact_.complete_velocities(sim);
      contact_.sum_remapped_into(vel_.data(), sim.threads);
      momentum_to_velocity(sim, vel_.data(), D, 0);
      contact_.velocities_from_momenta(sim, ContactFields<D>::Momentum::kRemap);
    } else {
      sim.complete_nodes({{vel_.data(), D, D}});
      momentum_to_velocity(sim, vel_.data(), D, 0);
    }
  }
  /// Where the particles of a set find their node records (stride S), velocities (stride D)
  /// and, with contact, volumes (stride G): the shared ones, or their body's field. Taken into a
  /// kernel's locals before its loop.
  template <Fields FIELDS>
  struct NodeArrays {
    double *records, *velocities, *volumes;
    const ContactFields<D>* fields;
    const uint16_t* body;
    LOAM_FORCE_INLINE double* record(size_t i) const { return records + offset(i, S); }
    LOAM_FORCE_INLINE double* velocity(size_t i) const { return velocities + offset(i, D); }
    LOAM_FORCE_INLINE double* volume(size_t i) const { return volumes + offset(i, G); }
    /// The FLIP share of particle i's velocity update: 0 for a rigid body's (PIC keeps its
    /// particles' velocities a rigid motion), else the scheme's.
    LOAM_FORCE_INLINE double flip(double blend, size_t i) const {
      if constexpr (FIELDS == Fields::kShared) return blend;
      return fields->rigid(body, i) ? 0.0 : blend;
    }
    LOAM_FORCE_INLINE size_t offset(size_t i, int width) const {
      if constexpr (FIELDS == Fields::kShared) return 0;
      return fields->offset(body, i, width);
    }
  };
  template <Fields FIELDS>
  NodeArrays<FIELDS> node_arrays(const Particles<D>& P) {
    if constexpr (FIELDS == Fields::kShared)
      return {node_.data(), vel_.data(), nullptr, nullptr, nullptr};
    return {contact_.records(), contact_.velocities(), contact_.volumes(), &contact_,
            P.body.data()};
  }

  // ------------------------------------------------------------------ the phases
  /// P2G over every set: mass and momentum, internal, gravity and external forces (WHAT), all
  /// sets summed onto the one node record (with contact: onto their bodies' fields, with their
  /// volume and its gradient).
  template <int NPP, Scatter WHAT, Fields FIELDS>
  void scatter_all(Simulation<D>& sim) {
    if (fbar_.on()) sim.timed("fbar", [&] { fbar_before_scatter<WHAT, FIELDS>(sim); });
    // APIC's P2G is its own instantiation per form: the FLIP loop stays as it is without it.
    // Contact takes FLIP only (setup).
    sim.scatter_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
      affine_.template evaluate_with_form<NPP>(
          sim, s.particles, b, c, scratch_[size_t(t)]->stencil, scatters_momentum(WHAT) && B_ >= 0,
          [&](auto form) {
            constexpr AffineForm FORM = decltype(form)::value;
            if constexpr (FIELDS == Fields::kShared || FORM == AffineForm::kOff)
              scatter<NPP, WHAT, FORM, FIELDS>(sim, s, b, c, t);
          });
    });
  }
  /// G2P velocity update (FLIP/PIC, or APIC's: update_velocity_apic); PASS kRemap scatters the
  /// new momentum into vel_ (MUSL), kUpdateAndMove moves the particles with the updated grid
  /// velocity.
  template <int NPP, VelocityPass PASS, Fields FIELDS>
  void update_velocities(Simulation<D>& sim, double dt) {
    auto f = [&](ParticleSet<D>& s, size_t b, int c, int t) {
      if (FIELDS == Fields::kPerBody || !affine_on_)
        return update_velocity<NPP, PASS, FIELDS>(sim, s, dt, b, c, t);
      StencilBlock<D>& st = scratch_[size_t(t)]->stencil;
      affine_.evaluate(sim, s.particles, b, c, st);
      affine_.template with_form<NPP>(st, [&](auto form) {
        update_velocity_apic<NPP, PASS, decltype(form)::value>(sim, s, dt, b, c, t);
      });
    };
    if constexpr (remaps(PASS))
      sim.scatter_blocks(f);
    else
      sim.gather_blocks(f);
  }
  /// What the gradient pass does besides the velocity gradient, volume and stress update.
  enum class Gradient {
    kRemapped,  // MUSL: L from the re-mapped velocity vel_; move with the updated grid velocity
    kCurrent,   // USF: L from vel_ (velocity at t^n); particles do not move here
    kUpdated,   // USL: L, move and FLIP update all from the updated grid record, in one pass
                // (with APIC the velocities are already updated: L and move only)
  };
  template <int NPP, Gradient MODE, Fields FIELDS>
  void update_stresses(Simulation<D>& sim, double dt) {
    if (fbar_.on()) fbar_.resize(sim);
    sim.gather_blocks([&](ParticleSet<D>& s, size_t b, int c, int t) {
      update_stress<NPP, MODE, FIELDS>(sim, s, dt, b, c, t);
    });
    if (fbar_.on()) sim.timed("fbar", [&] { update_stresses_fbar<FIELDS>(sim, dt); });
  }
  /// F-bar's groups of particles: one (the shared field), or each body's field with contact (a
  /// rigid body's particles in none); f(groups, group), group(set, i).
  template <Fields FIELDS, class F>
  void with_fbar_groups(Simulation<D>& sim, F&& f) {
    if constexpr (FIELDS == Fields::kShared) {
      f(1, [](size_t, size_t) { return 0; });
    } else {
      f(contact_.num_fields(), [this, &sim](size_t set, size_t i) {
        const uint16_t* body = sim.sets[set].particles.body.data();
        return contact_.rigid(body, i) ? Fbar<D>::kNoGroup : contact_.field(body, i);
      });
    }
  }
  /// F-bar at a scatter: where the particles are (the step's first scatter), and the mean
  /// stress projected for the internal force (framework/fbar.hpp).
  template <Scatter WHAT, Fields FIELDS>
  void fbar_before_scatter(Simulation<D>& sim) {
    with_fbar_groups<FIELDS>(sim, [&](int groups, auto group) {
      if (scatters_momentum(WHAT)) fbar_.locate(sim, groups, group);
      if (scatters_force(WHAT)) fbar_.project_mean_stress(sim, group);
    });
  }
  /// F-bar (framework/fbar.hpp): the kept velocity gradients' volume ratios projected per
  /// velocity field, then each particle's volume, F and stress from its L_bar.
  template <Fields FIELDS>
  void update_stresses_fbar(Simulation<D>& sim, double dt) {
    with_fbar_groups<FIELDS>(sim,
                             [&](int, auto group) { fbar_.project_volume_ratios(sim, group); });
    sim.gather_blocks([&](ParticleSet<D>& set, size_t b, int count, int thread) {
      Particles<D>& P = set.particles;
      double* L = scratch_[size_t(thread)]->L.data();
      double* V = P.col(P.volume) + b;
      const auto F = deformation_gradient_block(P, F_, b);
      const size_t slot = sim.set_slot(set);
      for (int p = 0; p < count; ++p) {
        double l[D][D];
        fbar_.averaged_gradient(slot, b + size_t(p), dt, l);
        store_velocity_gradient<D>(l, L, p);
        update_volume_and_deformation<D>(l, dt, V[p], F, p);
      }
      sim.update_block_stress(set, b, count, dt, L);
    });
  }

  // ------------------------------------------------------------------ kernels
  /// Particle-to-grid for one evaluated block: mass and momentum (with an affine FORM: APIC's),
  /// forces, as WHAT says.
  template <int NPP, Scatter WHAT, AffineForm FORM, Fields FIELDS>
  [[gnu::noinline]] void scatter(Simulation<D>& sim, ParticleSet<D>& set, size_t b, int count,
                                 int thread) {
    constexpr bool AFFINE = FORM != AffineForm::kOff;
    constexpr bool MOMENTUM = scatters_momentum(WHAT), FORCE = scatters_force(WHAT);
    Particles<D>& P = set.particles;
    const StencilBlock<D>& st = scratch_[size_t(thread)]->stencil;
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
    // F-bar: the projected mean stress in the force (Fbar::project_mean_stress).
    const double* shift = FORCE && fbar_.on() ? fbar_.shifts(sim.set_slot(set)) + b : nullptr;
    const std::array<double, D> gravity = sim.gravity;
    typename AffineTransfer<D>::Stencil as;
    typename AffineTransfer<D>::template Momenta<NPP, FORM> am;  // APIC: momenta per weight
    typename AffineTransfer<D>::Columns Bp;
    if constexpr (AFFINE) Bp = AffineTransfer<D>::columns(P, B_);
    const auto nodes = node_arrays<FIELDS>(P);
    for (int p = 0; p < count; ++p) {
      double* g = nodes.record(b + size_t(p));
      double* volume = nodes.volume(b + size_t(p));  // with contact: volume and its gradient
      // Particle values in locals: the node stores below could alias the particle columns.
      const double mp = m[p];
      double mv[D], body[D], sv[D][D];
      for (int d = 0; d < D; ++d) {
        mv[d] = mp * v[size_t(d)][p];
        body[d] = mp * gravity[size_t(d)] + (fe[size_t(d)] ? fe[size_t(d)][p] : 0.0);
        for (int j = 0; j < D; ++j) sv[d][j] = V[p] * sig[size_t(voigt_index(d, j))][p];
      }
      if (shift)
        for (int d = 0; d < D; ++d) sv[d][d] += V[p] * shift[p];
      if constexpr (AFFINE) {  // APIC: m_p (N v_p + B_p D_p^-1 N (x_I - x_p)), see the header
        double mC[D][D];       // m_p B_p D_p^-1
        affine_.stencil(P, st, p, b + size_t(p), npp, as);
        affine_.matrix(Bp, b + size_t(p), mp, as, mC);
        AffineTransfer<D>::template momenta<NPP>(as, npp, mv, mC, am);
      }
      // Stencil entry k's share: mass, the momentum per unit weight momentum(d), forces.
      auto add_entry = [&](int k, auto momentum) __attribute__((always_inline)) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const double w = st.w[kp];
        double* r = g + size_t(st.node[kp]) * S;
        if constexpr (MOMENTUM) {
          r[kMass] += w * mp;
          for (int d = 0; d < D; ++d) r[kMomentum + d] += w * momentum(d);
          if constexpr (FIELDS == Fields::kPerBody) {
            double* vI = volume + size_t(st.node[kp]) * G;
            vI[ContactFields<D>::kVolume] += w * V[p];
            for (int d = 0; d < D; ++d)
              vI[ContactFields<D>::kGradient + d] +=
                  V[p] * st.grad[(size_t(k) * D + size_t(d)) * kBlock + size_t(p)];
          }
        }
        if constexpr (FORCE) {
          double gr[D];
          for (int j = 0; j < D; ++j)
            gr[j] = st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
          for (int d = 0; d < D; ++d) {
            double f = w * body[d];
            for (int j = 0; j < D; ++j) f -= sv[d][j] * gr[j];  // f_int = -V sigma . grad N
            r[kForce + d] += f;
          }
        }
      };
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            if constexpr (AFFINE)
              add_entry(k, [&](int d) { return am.at(k, d); });
            else
              add_entry(k, [&](int d) { return mv[d]; });
          });
    }
  }

  /// Nodal forces to updated velocity and acceleration, with loads, face forces, damping and
  /// the boundary conditions: v^{n+1} = (p + dt f) / m, a = f / m; a node lighter than
  /// mass_tolerance keeps p / m without acceleration (light_node_velocity_scale).
  template <Fields FIELDS>
  void update_nodes(Simulation<D>& sim, double dt) {
    sim.apply_grid_loads(node_vector(kForce));
    GridForces forces;
    forces.mixture = node_vector(kForce);
    forces.mass = node_vector(kMass);
    forces.momentum = node_vector(kMomentum);
    sim.apply_boundary_forces(forces);
    // Where a rigid body holds another up: left undamped, and the contact update tries the
    // exchange there first.
    const std::vector<size_t>* supported = nullptr;
    if constexpr (FIELDS == Fields::kPerBody) supported = &contact_.supported_nodes(sim);
    sim.apply_damping(NodeForces{node_.data(), node_vector(kMomentum), node_vector(kForce),
                                 sim.grid.num_nodes, S},
                      supported);
    const double tol = sim.mass_tolerance;
    double* g = node_.data();
    for_each_node(sim.grid.num_nodes, sim.threads, [=](size_t i) {
      double* r = g + i * S;
      if (r[kMass] > tol) {
        const double inv = 1.0 / r[kMass];
        for (int d = 0; d < D; ++d) {
          const double a = r[kForce + d] * inv;
          r[kMomentum + d] = r[kMomentum + d] * inv + dt * a;
          r[kForce + d] = a;
        }
      } else {
        const double v_scale = light_node_velocity_scale(r[kMass]);
        for (int d = 0; d < D; ++d) {
          r[kMomentum + d] *= v_scale;
          r[kForce + d] = 0.0;
        }
      }
    });
    GridUpdate u;
    u.phases[0] = {node_vector(kMomentum), node_vector(kForce), node_vector(kMass)};
    u.dt = dt;
    sim.constrain_update(u);
    if constexpr (FIELDS == Fields::kPerBody) contact_.update(sim, node_.data(), dt);
  }

  /// Velocity from momentum in vel_ (MUSL re-map, USF), constrained: every node with mass
  /// (update_nodes says why the light ones too).
  void momentum_to_velocity(Simulation<D>& sim, const double* momentum, int stride, int offset) {
    const double tol = sim.mass_tolerance;
    const double* node = node_.data();
    double* vel = vel_.data();
    for_each_node(sim.grid.num_nodes, sim.threads, [=](size_t i) {
      const double m = node[i * S + kMass];
      for (int d = 0; d < D; ++d)
        vel[i * D + size_t(d)] =
            node_velocity(momentum[i * size_t(stride) + size_t(offset + d)], m, tol);
    });
    sim.constrain(vel_vector());
  }

  /// Grid-to-particle velocity update of one block (FLIP/PIC blend); PASS as in
  /// update_velocities (a move never crosses a held face: Simulation::held_faces).
  template <int NPP, VelocityPass PASS, Fields FIELDS>
  void update_velocity(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count,
                       int thread) {
    constexpr bool REMAP = remaps(PASS), MOVE = moves(PASS);
    Particles<D>& P = set.particles;
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
    // Locals, not members: the stores through v and x could alias them and force reloads.
    const double flip = flip_;
    const HeldFaces<D> walls = sim.held_faces;
    double max_v2 = sc.max_v2, loss = 0;
    const auto nodes = node_arrays<FIELDS>(P);
    for (int p = 0; p < count; ++p) {
      const double* g = nodes.record(b + size_t(p));
      double* remap = nodes.velocity(b + size_t(p));
      double a[D] = {}, vn[D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const double w = st.w[kp];
        const double* r = g + size_t(st.node[kp]) * S;
        for (int d = 0; d < D; ++d) {
          vn[d] += w * r[kMomentum + d];
          a[d] += w * r[kForce + d];
        }
      }
      double v2 = 0, vp[D];
      // A rigid body's particles take PIC; the ledger counts its energy as the body's.
      const double share = nodes.flip(flip, b + size_t(p));
      for (int d = 0; d < D; ++d) {
        vp[d] = flip_pic(share, v[size_t(d)][p], dt, a[d], vn[d]);
        if (share < 1 && share == flip)
          loss += m[p] * transfer_loss(v[size_t(d)][p], dt, a[d], vp[d]);
        v[size_t(d)][p] = vp[d];
        v2 += vp[d] * vp[d];
        if constexpr (MOVE) x[size_t(d)][p] = walls.moved(d, x[size_t(d)][p], dt * vn[d]);
      }
      max_v2 = std::max(max_v2, v2);
      if constexpr (REMAP) {
        const double mp = m[p];
        for (int k = 0; k < npp; ++k) {
          const size_t kp = size_t(k) * kBlock + size_t(p);
          const double wm = st.w[kp] * mp;
          double* r = remap + size_t(st.node[kp]) * D;
          for (int d = 0; d < D; ++d) r[d] += wm * vp[d];
        }
      }
    }
    sc.max_v2 = max_v2;
    if (flip < 1) sim.ledger.add_transfer_loss(sim.set_slot(set), b, 0.5 * loss);
  }

  /// APIC grid-to-particle update of one evaluated block (the header's equations) from the
  /// updated grid velocities; PASS kRemap: the MUSL re-map of the new particle momenta, affine
  /// part included, into vel_; kUpdateAndMove: the move (after B_p is taken at the old position).
  template <int NPP, VelocityPass PASS, AffineForm FORM>
  void update_velocity_apic(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count,
                            int thread) {
    constexpr bool REMAP = remaps(PASS), MOVE = moves(PASS);
    Particles<D>& P = set.particles;
    Scratch& sc = *scratch_[size_t(thread)];
    const StencilBlock<D>& st = sc.stencil;
    const int npp = NPP ? NPP : st.npp;
    const double* g = node_.data();
    double* remap = vel_.data();
    const HeldFaces<D> walls = sim.held_faces;
    double max_v2 = sc.max_v2;
    typename AffineTransfer<D>::Stencil as;
    typename AffineTransfer<D>::template Momenta<NPP, FORM> am;  // the re-map's, per weight
    const auto Bp = AffineTransfer<D>::columns(P, B_);
    const double* m = P.col(P.mass);
    std::array<double*, D> v{}, x{};
    for (int d = 0; d < D; ++d) {
      v[size_t(d)] = P.col(P.velocity, d);
      x[size_t(d)] = P.col(P.position, d);
    }
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      double vp[D] = {}, B[D][D];
      typename AffineTransfer<D>::template MomentSum<NPP, FORM> sum;
      sum.clear();
      affine_.stencil(P, st, p, i, npp, as);
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            const double w = st.w[kp];
            const double* vI = g + size_t(st.node[kp]) * S + kMomentum;
            for (int d = 0; d < D; ++d) vp[d] += w * vI[d];
            affine_.add_moment(sum, st, k, p, w, vI, as);
          });
      affine_.moment(sum, as, B);
      double v2 = 0, mv[D], mC[D][D];
      const double mp = m[i];
      if (!affine_.needs_usf()) Bp.store(i, B);  // linear: the USF gradient pass
      for (int d = 0; d < D; ++d) {
        v[size_t(d)][i] = vp[d];
        mv[d] = mp * vp[d];
        v2 += vp[d] * vp[d];
        if constexpr (MOVE) x[size_t(d)][i] = walls.moved(d, x[size_t(d)][i], dt * vp[d]);
      }
      max_v2 = std::max(max_v2, v2);
      if constexpr (!REMAP) continue;
      affine_.matrix(mp, B, as, mC);
      AffineTransfer<D>::template momenta<NPP>(as, npp, mv, mC, am);
      for_each_entry<FORM>(
          npp, [&](int k) __attribute__((always_inline)) {
            const size_t kp = size_t(k) * kBlock + size_t(p);
            double* r = remap + size_t(st.node[kp]) * D;
            for (int d = 0; d < D; ++d) r[d] += st.w[kp] * am.at(k, d);
          });
    }
    sc.max_v2 = max_v2;
  }

  /// Velocity gradient, volume and F update, optional move / velocity update, and the
  /// material's stress update for one block.
  template <int NPP, Gradient MODE, Fields FIELDS>
  void update_stress(Simulation<D>& sim, ParticleSet<D>& set, double dt, size_t b, int count,
                     int thread) {
    constexpr bool kMove = MODE != Gradient::kCurrent;
    constexpr bool kFromRecord = MODE == Gradient::kUpdated;
    Particles<D>& P = set.particles;
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
    const auto F = deformation_gradient_block(P, F_, b);
    const size_t vstride = kFromRecord ? S : D;
    const double flip = flip_;
    const bool apic = affine_on_;  // USL with APIC: the velocities are updated already
    const HeldFaces<D> walls = sim.held_faces;
    const bool fbar = fbar_.on();
    const size_t slot = sim.set_slot(set);
    double max_v2 = sc.max_v2, loss = 0;
    // Linear tents with an affine transfer: the gradient is the particle's C_p.
    const bool store_C = MODE == Gradient::kCurrent && B_ >= 0 && affine_.needs_usf();
    typename AffineTransfer<D>::Columns C;
    if (store_C) C = AffineTransfer<D>::columns(P, B_);
    const auto nodes = node_arrays<FIELDS>(P);
    for (int p = 0; p < count; ++p) {
      const double* g = nodes.record(b + size_t(p));
      // Source of the velocity field whose gradient is taken.
      const double* vel = kFromRecord ? g + kMomentum : nodes.velocity(b + size_t(p));
      double l[D][D] = {}, vn[D] = {}, a[D] = {};
      for (int k = 0; k < npp; ++k) {
        const size_t kp = size_t(k) * kBlock + size_t(p);
        const size_t n = size_t(st.node[kp]);
        add_velocity_gradient<D>(l, vel + n * vstride, st, size_t(k), p);
        if constexpr (kMove) {
          const double w = st.w[kp];
          for (int d = 0; d < D; ++d) vn[d] += w * g[n * S + kMomentum + size_t(d)];
          if constexpr (kFromRecord)
            for (int d = 0; d < D; ++d) a[d] += w * g[n * S + kForce + size_t(d)];
        }
      }
      if (store_C) C.store(b + size_t(p), l);
      if (fbar) {
        fbar_.keep(slot, b + size_t(p), l, dt);  // update_stresses_fbar
      } else {
        store_velocity_gradient<D>(l, L, p);
        update_volume_and_deformation<D>(l, dt, V[p], F, p);
      }
      if constexpr (kMove)
        for (int d = 0; d < D; ++d) x[size_t(d)][p] = walls.moved(d, x[size_t(d)][p], dt * vn[d]);
      if (kFromRecord && !apic) {
        double v2 = 0;
        const double share = nodes.flip(flip, b + size_t(p));  // PIC for a rigid body's
        for (int d = 0; d < D; ++d) {
          double& vp = v[size_t(d)][p];
          const double v_old = vp;
          vp = flip_pic(share, vp, dt, a[d], vn[d]);
          if (share < 1 && share == flip)
            loss += P.col(P.mass)[b + size_t(p)] * transfer_loss(v_old, dt, a[d], vp);
          v2 += vp * vp;
        }
        max_v2 = std::max(max_v2, v2);
      }
    }
    sc.max_v2 = max_v2;
    if (flip < 1) sim.ledger.add_transfer_loss(slot, b, 0.5 * loss);
    if (!fbar) sim.update_block_stress(set, b, count, dt, L);
  }
};

LOAM_REGISTER_DEFAULT(Scheme, SinglePhase)

}  // namespace loam
