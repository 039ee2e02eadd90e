#pragma once
// Multi-velocity-field contact (Bardenhagen et al. 2000, 2001; docs/contact.md). Each body in
// contact scatters its mass, momentum and forces, its nodal volume sum_p V_p N_I(x_p) and the
// volume gradient g = sum_p V_p grad N_I(x_p) onto a field of its own; the bodies not in contact
// share one. The centre record (the sum of the fields) gets the loads, face forces, damping and
// boundary conditions as without contact; then at every node where two fields have mass
//   v_f* = (p_f + dt f_f) / m_f,
//   v_f  = v_f* + (v_cm - sum_f m_f v_f* / m)    (what the centre got beyond the fields' forces),
// the components a condition holds are set to the centre's, and each pair of fields exchanges
// momentum by the contact law (framework/contact.hpp) along one normal n from a towards b (one
// for both, so the exchange conserves momentum exactly): the outward normal g / |g| of the field
// with the larger nodal volume, g_a or -g_b (grad N_I(x_p) at a node outside a body points away
// from it), among the choices Nairn (2013, "Modeling imperfect interfaces in the material point
// method using multimaterial methods") compares. The flat face of one body then sets the normal
// where the corner of the other reaches the node; the mean of the two normals, or the larger
// gradient, made that corner a ramp (a block sliding over a slab hopped at each cell it crossed).
// A pair not in contact moves with its centre of mass. A node with one field keeps the centre's
// velocity and acceleration, so away from contact the particles see the shared field bitwise.
// The particles of a field take its velocity and acceleration a_f = (v_f - p_f / m_f) / dt.
//
// A rigid body's field (framework/rigid_fields.hpp) stays out of the centre record and moves
// as one piece; the other fields meet it as a body of infinite mass (the law gets m_b =
// +infinity: the rigid field keeps its velocity, the other takes the whole exchange). Its
// particles take PIC from it, so their velocities stay a rigid motion. Two rigid bodies pass
// through each other.
#include <omp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "contact.hpp"
#include "diagnostics.hpp"
#include "grid.hpp"
#include "rigid_fields.hpp"
#include "simulation.hpp"
#include "step_blocks.hpp"

namespace loam {

/// Whether a kernel's particles share the one nodal record or each body in contact has its own.
enum class Fields { kShared, kPerBody };

template <int D>
class ContactFields {
 public:
  /// The node record of a field, as the single-phase scheme's: mass, momentum (D), force (D);
  /// after the update the momentum slot holds the velocity, the force slot the acceleration.
  static constexpr int kMass = 0, kMomentum = 1, kForce = 1 + D, S = 1 + 2 * D;
  /// Per node and field, the volume sum_p V_p N_I(x_p) and its gradient sum_p V_p grad N_I(x_p).
  static constexpr int kVolume = 0, kGradient = 1, G = 1 + D;

  bool on() const { return law_ != nullptr; }

  /// One field per body named by the law (every body if it names none), one shared by the rest;
  /// unknown names are located errors at `where`.
  void setup(Simulation<D>& sim, const Params& where, Diagnostics& diag) {
    law_ = sim.contact.get();
    nodes_ = sim.grid.num_nodes;
    cell_volume_ = 1;
    for (int d = 0; d < D; ++d) cell_volume_ *= sim.grid.cell[d];
    const auto& names = law_->bodies();
    std::vector<uint8_t> listed(sim.bodies.size(), names.empty() ? 1 : 0);
    for (size_t i = 0; i < names.size(); ++i) {
      size_t b = 0;
      while (b < sim.bodies.size() && sim.bodies[b].name != names[i]) ++b;
      if (b == sim.bodies.size())
        diag.error(where.where("bodies", i), where.path("bodies") + "." + std::to_string(i),
                   "no body named '" + names[i] + "'");
      else
        listed[b] = 1;
    }
    field_of_body_.assign(sim.bodies.size(), 0);
    bool shared = false;
    for (uint8_t l : listed) shared = shared || !l;
    fields_ = shared ? 1 : 0;
    touches_.assign(1, 0);
    for (size_t b = 0; b < sim.bodies.size(); ++b)
      if (listed[b]) {
        field_of_body_[b] = fields_++;
        touches_.resize(size_t(fields_), 0);
        touches_.back() = 1;
      }
    if (fields_ > kMaxFields)
      diag.error(where.where("bodies"), where.path("bodies"),
                 "at most " + std::to_string(kMaxFields) +
                     " velocity fields: the bodies in contact and one for the others");
    if (!diag.ok()) return;
    rigid_.setup(sim, fields_, field_of_body_);
    rec_.assign(size_t(fields_) * nodes_ * S, 0.0);
    volume_.assign(size_t(fields_) * nodes_ * G, 0.0);
    vel_.assign(size_t(fields_) * nodes_ * D, 0.0);
    touching_.assign(nodes_, 0);
  }

  /// Whether particle i's body moves rigidly in this step.
  bool rigid(const uint16_t* body, size_t i) const { return rigid_.body_is_rigid(body[i]); }
  /// Offset of particle i's field in an array of `width` values per node and field.
  size_t offset(const uint16_t* body, size_t i, int width) const {
    return size_t(field_of_body_[body[i]]) * nodes_ * size_t(width);
  }
  /// The velocity field of particle i's body, and how many fields there are.
  int field(const uint16_t* body, size_t i) const { return field_of_body_[body[i]]; }
  int num_fields() const { return fields_; }
  double* records() { return rec_.data(); }
  double* volumes() { return volume_.data(); }
  double* velocities() { return vel_.data(); }

  /// A new step: the bodies that move rigidly in it (their conditions active now), their mass,
  /// centre and inertia; the records and volumes zeroed for the scatter.
  void begin_step(const Simulation<D>& sim) {
    rigid_.find(sim);
    zero_nodes(rec_, sim.threads);
    zero_nodes(volume_, sim.threads);
  }
  void zero_velocities(int threads) { zero_nodes(vel_, threads); }

  /// Complete the fields' sums over the ranks: record slots [first, first + width), with the
  /// volumes when `volumes`.
  void complete(Simulation<D>& sim, int first, int width, bool volumes) {
    std::vector<NodalArray> a;
    for (int f = 0; f < fields_; ++f) {
      a.push_back({rec_.data() + size_t(f) * nodes_ * S, S, width, first});
      if (volumes) a.push_back({volume_.data() + size_t(f) * nodes_ * G, G, G});
    }
    sim.complete_nodes(a);
  }
  /// Complete the re-mapped momenta in velocities() over the ranks.
  void complete_velocities(Simulation<D>& sim) {
    std::vector<NodalArray> a;
    for (int f = 0; f < fields_; ++f) a.push_back({vel_.data() + size_t(f) * nodes_ * D, D, D});
    sim.complete_nodes(a);
  }
  /// The centre record's slots [first, first + width) as the sum of the fields' (rigid bodies'
  /// left out).
  void sum_into(double* centre, int first, int width, int threads) const {
    sum_fields(rec_.data(), S, first, width, centre, threads);
  }
  /// The fields' re-mapped momenta summed into `centre` (D per node): the shared field's.
  void sum_remapped_into(double* centre, int threads) const {
    sum_fields(vel_.data(), D, 0, D, centre, threads);
  }

  /// The nodes where a rigid body's field and another field have mass (the rigid body holds
  /// that field there; Simulation::apply_damping leaves them); none without rigid bodies.
  /// Found once a step, after the scatter and before the update, which tries the exchange there
  /// (find_bonds).
  const std::vector<size_t>& supported_nodes(const Simulation<D>& sim) {
    supported_.clear();
    if (!rigid_.any()) return supported_;
    const double tol = sim.mass_tolerance;
    int first_overlap[2] = {-1, -1};
    for (size_t n = 0; n < nodes_; ++n) {
      int rigid = 0, last_rigid = -1;
      bool other = false;
      for (int f = 0; f < fields_; ++f) {
        const bool mass = rec_[(size_t(f) * nodes_ + n) * S + kMass] > tol;
        if (!mass) continue;
        if (!rigid_.field_is_rigid(f)) {
          other = true;
        } else {
          if (++rigid == 2 && first_overlap[0] < 0)
            first_overlap[0] = last_rigid, first_overlap[1] = f;
          last_rigid = f;
        }
      }
      if (rigid > 0 && other) supported_.push_back(n);
    }
    if (first_overlap[0] >= 0) warn_rigid_bodies_meet(sim, first_overlap[0], first_overlap[1]);
    return supported_;
  }

  /// The fields' updated velocities and accelerations from the centre's (updated and
  /// constrained: velocity in its momentum slot, acceleration in its force slot), the header's
  /// equations; the contact's work goes to the energy ledger. After this step's
  /// supported_nodes().
  void update(Simulation<D>& sim, const double* centre, double dt) {
    if (rigid_.any()) {
      rigid_.predict(sim, rec_.data(), centre, dt);
      find_bonds(sim, centre, dt);
      rigid_.couple(sim, rec_.data());
    }
    const double tol = sim.mass_tolerance;
    const HeldComponents& held = sim.held(0);
    const int F = fields_;
    const size_t region = nodes_ * S;
    double* rec = rec_.data();
    EnergyLedger<D>& ledger = sim.ledger;
    uint8_t* touching = touching_.data();
    const int* rigid = rigid_.of_field();
    for_each_node(nodes_, sim.threads, [&, F, region, rec, tol, dt, touching, rigid](size_t n) {
      touching[n] = 0;
      const double* c = centre + n * S;
      double m[kMaxFields], v[kMaxFields][D], vn[kMaxFields][D];
      const int with_mass = node_state(n, c, tol, dt, m, v, vn);
      if (with_mass > 1 && c[kMass] > tol) {
        before_exchange(n, c, m, v, held);
        double before[kMaxFields][D];
        std::copy(&v[0][0], &v[0][0] + F * D, &before[0][0]);
        exchange_at(n, held, c, m, v);
        for (int f = 0; f < F; ++f)
          for (int d = 0; d < D; ++d) touching[n] |= v[f][d] != before[f][d];
        if (ledger.enabled) ledger.add_contact(n, contact_dissipation(m, vn, before, v, F));
      }
      for (int f = 0; f < F; ++f) {
        if (rigid[f] >= 0) continue;  // RigidFields::correct
        double* r = rec + size_t(f) * region + n * S;
        const bool own = with_mass > 1 && c[kMass] > tol && m[f] > 0;
        for (int d = 0; d < D; ++d) {
          r[kMomentum + d] = own ? v[f][d] : c[kMomentum + d];
          r[kForce + d] = own ? (v[f][d] - vn[f][d]) / dt : c[kForce + d];
        }
      }
    });
    if (rigid_.any()) rigid_.correct(sim, rec_.data(), dt);
  }

  /// The fields' velocities p_f / m_f, constrained, with the contact exchange, into
  /// velocities(): from the record's momentum slot before the grid update (`kRecord`, USF),
  /// the law judging the approach; or from the re-mapped momenta in velocities() (`kRemap`,
  /// MUSL) at the nodes where the update found the fields in contact, the law told so. Judged
  /// again, the re-map lets a node go that the update held: the strain then disagrees with the
  /// motion (two elastic bars rebounded with 40 % more energy than they had). Taking the
  /// update's velocities there instead is USL's light-node instability (f / m at a node two
  /// bodies barely reach).
  enum class Momentum { kRecord, kRemap };
  void velocities_from_momenta(Simulation<D>& sim, Momentum source) {
    const double tol = sim.mass_tolerance;
    const int F = fields_;
    const size_t region = nodes_ * S;
    const double* rec = rec_.data();
    double* vel = vel_.data();
    const bool remap = source == Momentum::kRemap;
    for_each_node(nodes_, sim.threads, [=, this](size_t n) {
      for (int f = 0; f < F; ++f) {
        const double* r = rec + size_t(f) * region + n * S;
        double* v = vel + (size_t(f) * nodes_ + n) * D;
        for (int d = 0; d < D; ++d)
          v[d] = node_velocity(remap ? v[d] : r[kMomentum + d], r[kMass], tol);
      }
    });
    constrain_velocities(sim);
    rigid_.set_velocities(rec, vel, !remap);  // USF: the motion at t^n
    const uint8_t* touching = touching_.data();
    const HeldComponents& held = sim.held(0);
    for_each_node(nodes_, sim.threads, [=, this, &held](size_t n) {
      double m[kMaxFields], v[kMaxFields][D];
      int with_mass = 0;
      for (int f = 0; f < F; ++f) {
        m[f] = rec[size_t(f) * region + n * S + kMass];
        m[f] = m[f] > tol ? m[f] : 0.0;
        with_mass += m[f] > 0;
        for (int d = 0; d < D; ++d) v[f][d] = vel[(size_t(f) * nodes_ + n) * D + size_t(d)];
      }
      if (with_mass < 2 || (remap && !touching[n])) return;
      exchange_pairs(n, m, v, remap ? Approach::kFound : Approach::kJudged, held, nullptr);
      for (int f = 0; f < F; ++f)
        if (m[f] > 0 && !rigid_.field_is_rigid(f))
          for (int d = 0; d < D; ++d) vel[(size_t(f) * nodes_ + n) * D + size_t(d)] = v[f][d];
    });
    constrain_velocities(sim);  // the exchange may have moved a held component
  }

 private:
  const Contact<D>* law_ = nullptr;
  int fields_ = 0;
  size_t nodes_ = 0;
  double cell_volume_ = 1;  // h^D
  std::vector<int> field_of_body_;
  std::vector<uint8_t> touches_;   // per field: in contact with the other such fields
  std::vector<double> rec_;        // fields * nodes * S
  std::vector<double> volume_;     // fields * nodes * G: volume and volume gradient
  std::vector<uint8_t> touching_;  // per node: the last update's exchange changed a velocity
  std::vector<double> vel_;        // fields * nodes * D: re-mapped momenta, then velocities
  std::vector<size_t> supported_;  // supported_nodes()
  bool warned_rigid_meet_ = false;

  /// Two rigid bodies reach one node: contact between rigid bodies is not modelled, they pass
  /// through each other (docs/contact.md, Limits). Said once per run, not silently.
  void warn_rigid_bodies_meet(const Simulation<D>& sim, int field_a, int field_b) {
    if (warned_rigid_meet_) return;
    warned_rigid_meet_ = true;
    std::string names;
    for (size_t b = 0; b < field_of_body_.size(); ++b)
      if (field_of_body_[b] == field_a || field_of_body_[b] == field_b)
        names += (names.empty() ? "'" : " and '") + sim.bodies[b].name + "'";
    spdlog::warn(
        "t = {:.6g} s: the rigid bodies {} reach the same grid nodes; contact between rigid "
        "bodies is not modelled, they pass through each other (docs/contact.md, Limits)",
        sim.time, names);
  }
  RigidFields<D> rigid_;  // the fields of rigid bodies
  static_assert(RigidFields<D>::S == S && RigidFields<D>::kForce == kForce);

  static constexpr int kMaxFields = 8;
  /// A field with less volume at a node than this share of a cell's takes no part in contact
  /// there (pair_normal).
  static constexpr double kMinShare = 0.02;

  /// dst[n * stride + s] = sum over the fields of src's, for s in [first, first + width).
  void sum_fields(const double* src, int stride, int first, int width, double* dst,
                  int threads) const {
    const int F = fields_;
    const size_t region = nodes_ * size_t(stride);
    const int* rigid = rigid_.of_field();
    for_each_node(nodes_, threads, [=](size_t n) {
      for (int s = first; s < first + width; ++s) {
        double sum = 0;
        for (int f = 0; f < F; ++f)
          if (rigid[f] < 0) sum += src[size_t(f) * region + n * size_t(stride) + size_t(s)];
        dst[n * size_t(stride) + size_t(s)] = sum;
      }
    });
  }
  /// The conditions on each field's velocities (a rigid body's field takes them in its rows).
  void constrain_velocities(Simulation<D>& sim) {
    for (int f = 0; f < fields_; ++f)
      if (!rigid_.field_is_rigid(f))
        sim.constrain(NodalVector{vel_.data() + size_t(f) * nodes_ * D, D, 0});
  }

  /// At node n: each field's mass (0 below the tolerance), velocity at t^n (vn) and after its
  /// own forces (v; a rigid field's from its body's motion), the centre's where it has no
  /// mass; returns how many fields have mass.
  int node_state(size_t n, const double* c, double tol, double dt, double* m, double (*v)[D],
                 double (*vn)[D]) const {
    int with_mass = 0;
    const int* rigid = rigid_.of_field();
    for (int f = 0; f < fields_; ++f) {
      const double* r = rec_.data() + (size_t(f) * nodes_ + n) * S;
      m[f] = r[kMass] > tol ? r[kMass] : 0.0;
      with_mass += m[f] > 0;
      for (int d = 0; d < D; ++d) {
        vn[f][d] = m[f] > 0 ? r[kMomentum + d] / m[f] : c[kMomentum + d];
        v[f][d] = m[f] > 0 ? vn[f][d] + dt * r[kForce + d] / m[f] : c[kMomentum + d];
      }
      if (rigid[f] >= 0 && m[f] > 0) rigid_.velocity(f, n, v[f]);
    }
    return with_mass;
  }
  /// The fields follow the centre's update, and the components a condition holds take its
  /// velocity (the exchange starts from these).
  void before_exchange(size_t n, const double* c, const double* m, double (*v)[D],
                       const HeldComponents& held) const {
    const int* rigid = rigid_.of_field();
    follow_centre(c, m, v, fields_, rigid);
    for (int d = 0; d < D; ++d)
      if (held.held(n, d))
        for (int f = 0; f < fields_; ++f)
          if (rigid[f] < 0) v[f][d] = c[kMomentum + d];
  }
  /// The exchange the update will make where a rigid body meets another field, tried with the
  /// bodies at their predicted motion: which fields it binds to them and how (RigidFields::
  /// couple moves each body together with them), at this step's supported_nodes().
  void find_bonds(Simulation<D>& sim, const double* centre, double dt) {
    const double tol = sim.mass_tolerance;
    const HeldComponents& held = sim.held(0);
    for (size_t n : supported_) {
      const double* c = centre + n * S;
      double m[kMaxFields], v[kMaxFields][D], vn[kMaxFields][D];
      if (node_state(n, c, tol, dt, m, v, vn) < 2 || !(c[kMass] > tol)) continue;
      before_exchange(n, c, m, v, held);
      exchange_pairs(n, m, v, Approach::kJudged, held, nullptr, rigid_.bonds());
    }
  }
  /// Shift the fields' velocities so that their centre of mass moves with the centre's updated
  /// velocity (the loads, face forces, damping and conditions the centre got).
  static void follow_centre(const double* c, const double* m, double (*v)[D], int F,
                            const int* rigid) {
    double mass = 0, mv[D] = {};
    for (int f = 0; f < F; ++f) {
      if (rigid[f] >= 0) continue;  // not in the centre record
      mass += m[f];
      for (int d = 0; d < D; ++d) mv[d] += m[f] * v[f][d];
    }
    for (int d = 0; d < D; ++d) {
      const double shift = c[kMomentum + d] - mv[d] / mass;
      for (int f = 0; f < F; ++f)
        if (m[f] > 0 && rigid[f] < 0) v[f][d] += shift;
    }
  }
  /// Every two fields with mass exchange momentum: by the law where both are in contact (and a
  /// normal is found), else they move with their centre of mass. A rigid body's field enters
  /// as field b of infinite mass; the impulse the other field takes from it goes, reversed, to
  /// `impulse` (fields * nodes * D) when given, and how the exchange bound the field to it to
  /// `bonds` (RigidFields::record_bond).
  void exchange_pairs(size_t node, const double* m, double (*v)[D], Approach approach,
                      const HeldComponents& held, double* impulse, double* bonds = nullptr) const {
    constexpr double kRigid = std::numeric_limits<double>::infinity();
    for (int a = 0; a < fields_; ++a)
      for (int b = a + 1; b < fields_; ++b) {
        if (!(m[a] > 0 && m[b] > 0)) continue;
        const bool rigid_a = rigid_.field_is_rigid(a), rigid_b = rigid_.field_is_rigid(b);
        if (rigid_a && rigid_b) continue;
        const int s = rigid_a ? b : a, t = rigid_a ? a : b;  // t: the rigid one, if either is
        const bool rigid = rigid_a || rigid_b;
        const double ms = m[s], mt = rigid ? kRigid : m[t];
        double before[D] = {};
        if ((impulse || bonds) && rigid) std::copy(v[s], v[s] + D, before);
        double n[D];
        bool normal = false;
        if (!touches_[size_t(a)] || !touches_[size_t(b)]) {
          bond(ms, mt, v[s], v[t]);
        } else if ((normal = pair_normal(node, a, b, held, n))) {
          if (rigid_a)
            for (int d = 0; d < D; ++d) n[d] = -n[d];  // from s towards t
          law_->exchange(ms, mt, v[s], v[t], n, approach);
        }
        if (impulse && rigid)
          for (int d = 0; d < D; ++d)
            impulse[(size_t(t) * nodes_ + node) * D + size_t(d)] -= ms * (v[s][d] - before[d]);
        if (bonds && rigid)
          RigidFields<D>::record_bond(bonds, nodes_, s, t, node, before, v[s], v[t],
                                      normal ? n : nullptr);
      }
  }
  /// The exchange at node n, then the held components set to the centre's v_c again.
  void exchange_at(size_t n, const HeldComponents& held, const double* c, const double* m,
                   double (*v)[D]) {
    double* impulse = rigid_.impulses();
    exchange_pairs(n, m, v, Approach::kJudged, held, impulse);
    for (int d = 0; d < D; ++d)
      if (held.held(n, d))
        for (int f = 0; f < fields_; ++f) {
          if (!rigid_.field_is_rigid(f))
            v[f][d] = c[kMomentum + d];
          else if (impulse)  // the other fields do not keep what the exchange gave them here
            impulse[(size_t(f) * nodes_ + n) * D + size_t(d)] = 0;
        }
  }
  /// Both fields move with their centre of mass (mb infinite: with b).
  static void bond(double ma, double mb, double (&va)[D], double (&vb)[D]) {
    for (int d = 0; d < D; ++d)
      va[d] = vb[d] = std::isinf(mb) ? vb[d] : (ma * va[d] + mb * vb[d]) / (ma + mb);
  }
  /// The unit normal from field a towards field b at `node`: the outward normal g / |g| of the
  /// field with the larger nodal volume there (a flat face rather than the corner of the other
  /// body that reaches the node). False where the other field's volume is below kMinShare of a
  /// cell's, or the gradient is zero: the pair then moves freely there. A quadratic stencil
  /// reaches a row of nodes into the other body, where the side faces of that body would give
  /// the normal (a block on a slab stuck to it). The components a condition holds at the node
  /// are left out: a body cut by a held face (a symmetry plane) has a spurious gradient across
  /// it, which tilted the normal and slowed a block sliding along a slip face by 1.5 %.
  bool pair_normal(size_t node, int a, int b, const HeldComponents& held, double (&n)[D]) const {
    const double* ga = volume_.data() + (size_t(a) * nodes_ + node) * G;
    const double* gb = volume_.data() + (size_t(b) * nodes_ + node) * G;
    if (std::min(ga[kVolume], gb[kVolume]) < kMinShare * cell_volume_) return false;
    const bool from_a = ga[kVolume] >= gb[kVolume];
    const double* g = (from_a ? ga : gb) + kGradient;
    double len2 = 0;
    for (int d = 0; d < D; ++d) {
      n[d] = held.held(node, d) ? 0.0 : g[d];
      len2 += n[d] * n[d];
    }
    if (!(len2 > 0)) return false;
    const double scale = (from_a ? 1 : -1) / std::sqrt(len2);
    for (int d = 0; d < D; ++d) n[d] *= scale;
    return true;
  }
  /// The kinetic energy the contact forces took from the fields: minus their work
  /// m_f dv_f . (v_f^n + v_f^{n+1}) / 2 (the ledger's mid-step rule).
  static double contact_dissipation(const double* m, const double (*vn)[D],
                                    const double (*before)[D], const double (*after)[D], int F) {
    double work = 0;
    for (int f = 0; f < F; ++f)
      for (int d = 0; d < D; ++d)
        work += m[f] * (after[f][d] - before[f][d]) * 0.5 * (vn[f][d] + after[f][d]);
    return -work;
  }
};

}  // namespace loam
