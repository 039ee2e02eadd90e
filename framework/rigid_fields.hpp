#pragma once
// The velocity fields of rigid bodies under contact (docs/contact.md, framework/rigid_motion.hpp).
// A condition whose rigid_motion() names a body on a field of its own makes that field rigid in
// the step: the field stays out of the centre record (framework/contact_fields.hpp), and
//  1. predict: the body's mass, centre and metric come from its particles at x^n; its nodal
//     momenta and forces (gravity, particle loads; the internal forces add none) give its motion
//     after its own forces, projected on its rows (prescribed components; components a condition
//     holds at a node it reaches, at that node's held velocity);
//  2. couple: the exchange, tried at that motion, binds fields to it where they reach it (stuck:
//     every component; sliding: the normal one); the body moves together with those nodal
//     masses, in the metric M_q + K, K = sum_I m_I G_I^T P_I G_I, from the momentum they carry
//     (the exchange treats it as infinitely heavy: where those masses outweigh it, a footing's
//     rotation on the soil below it, moving it alone overshoots, and the rotation grew from
//     round-off by alternating sign each step);
//  3. the contact exchange meets it as a body of infinite mass at that motion, and records the
//     impulse each of the other fields takes from it per node (impulses());
//  4. correct: what those impulses add to the bound momentum (friction), summed as momentum and
//     angular momentum, moves it with the bound masses in the same metric, the bound fields
//     following its change of motion, P_I G_I dq; the rows are imposed again; its nodes get
//     u(x_I) and the acceleration (u - p / m) / dt. The rows'
//     forces are reactions: a held node's to the condition credited with that node, the
//     prescribed components' to the body's condition; their work and the impulses' go to the
//     energy ledger.
// Under mpirun every rank holds the body's particles and nodes in its block: the sums over
// particles and over the nodes it owns (each node counted once) are summed over the ranks, the
// held nodes' rows gathered in rank order, so every rank finds the same motion; each rank reports
// its own rows' forces, rank 0 the prescribed components' and the ledger's body terms.
#include <Eigen/Dense>
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "boundary.hpp"
#include "rigid_motion.hpp"
#include "simulation.hpp"

namespace loam {

template <int D>
class RigidFields {
 public:
  /// The field record (framework/contact_fields.hpp): mass, momentum (D), force (D).
  static constexpr int kMass = 0, kMomentum = 1, kForce = 1 + D, S = 1 + 2 * D;

  /// `fields` velocity fields on sim's grid (this rank's box of nodes); field_of_body: each
  /// body's field.
  void setup(const Simulation<D>& sim, int fields, const std::vector<int>& field_of_body) {
    grid_ = &sim.grid;
    ranks_ = sim.ranks.get();
    fields_ = fields;
    nodes_ = sim.grid.num_nodes;
    field_of_body_ = field_of_body;
    of_field_.assign(size_t(fields), -1);
    owned_.clear();
    if (ranks_->distributed())
      for (size_t n = 0; n < nodes_; ++n)
        owned_.push_back(ranks_->owns_node(sim.grid, sim.grid.node_ijk(n)) ? 1 : 0);
  }

  /// The active conditions that make a body rigid in this step; each body's mass, centre and
  /// metric from its particles.
  void find(const Simulation<D>& sim) {
    bodies_.clear();
    of_field_.assign(size_t(fields_), -1);
    rigid_body_.assign(sim.bodies.size(), 0);
    for (const auto& b : sim.boundaries) {
      const RigidMotion<D>* motion = b->rigid_motion();
      if (!motion) continue;
      Rigid r;
      r.condition = b.get();
      r.motion = motion;
      r.field = field_of_body_[size_t(motion->rigid_body())];
      of_field_[size_t(r.field)] = int(bodies_.size());
      rigid_body_[size_t(motion->rigid_body())] = 1;
      bodies_.push_back(std::move(r));
    }
    if (bodies_.empty()) return;
    if (impulse_.empty()) impulse_.assign(size_t(fields_) * nodes_ * D, 0.0);
    if (bond_.empty()) bond_.assign(size_t(fields_) * nodes_ * kBond, 0.0);
    measure(sim);
    drop_empty_bodies();
  }

  bool any() const { return !bodies_.empty(); }
  /// Per field: its rigid body's entry (>= 0), or -1 (a deformable field).
  const int* of_field() const { return of_field_.data(); }
  bool field_is_rigid(int f) const { return of_field_[size_t(f)] >= 0; }
  /// Whether body b moves rigidly in this step.
  bool body_is_rigid(uint16_t b) const { return rigid_body_[b] != 0; }
  /// Per field and node, D: the impulse the exchange gave a rigid field (minus what the other
  /// fields took).
  double* impulses() { return impulse_.data(); }
  /// Per field and node, kBond: how the exchange bound the field to a rigid body (record_bond).
  double* bonds() { return bond_.data(); }
  static constexpr int kBond = 2 + 2 * D;
  /// The exchange at `node` moved field s from `before` to `after` against rigid field t moving
  /// at u there, along the normal n (nullptr: bonded, no normal): it is bound to t in every
  /// component where it now moves with it (stuck), else in the normal one (sliding); its
  /// velocity before the exchange is kept.
  static void record_bond(double* bonds, size_t nodes, int s, int t, size_t node,
                          const double (&before)[D], const double (&after)[D], const double (&u)[D],
                          const double* n) {
    double moved = 0, rel = 0, scale = 0;
    for (int d = 0; d < D; ++d) {
      moved += (after[d] - before[d]) * (after[d] - before[d]);
      rel += (after[d] - u[d]) * (after[d] - u[d]);
      scale += (before[d] - u[d]) * (before[d] - u[d]) + u[d] * u[d] + before[d] * before[d];
    }
    if (!(moved > 0)) return;
    double* b = bonds + (size_t(s) * nodes + node) * kBond;
    b[0] = t + 1;
    b[1] = !n || rel <= 1e-20 * scale ? 1 : 0;
    for (int d = 0; d < D; ++d) b[2 + d] = n ? n[d] : 0.0, b[2 + D + d] = before[d];
  }

  /// Step 2 (the header) from the bonds the tried exchange recorded.
  void couple(Simulation<D>& sim, const double* records) {
    const HeldComponents& held = sim.held(0);
    for (Rigid& r : bodies_) {
      r.bound.setZero();
      typename Dofs::Vector carried = Dofs::Vector::Zero();  // sum G^T m P v
      for (size_t n : r.nodes) {
        if (!owned(n)) continue;
        const typename Dofs::Map g = map_at(r, n);
        for (int f = 0; f < fields_; ++f) {
          const Eigen::Matrix<double, D, D> mp = bound_mass(r, records, held, f, n);
          if (mp.isZero()) continue;
          r.bound += g.transpose() * mp * g;
          carried += g.transpose() * mp * Column(bond(f, n) + 2 + D);
        }
      }
      ranks_->sum(r.bound.data(), Dofs::Q * Dofs::Q);
      ranks_->sum(carried.data(), Dofs::Q);
      r.joined = r.metric + r.bound;
      r.pred = r.q;
      if (r.bound.isZero()) continue;
      const typename Dofs::Vector free = Dofs::solve(r.joined, r.metric * r.q + carried);
      Eigen::VectorXd rows;
      r.q = r.rows.constrained(free, r.joined, rows);
      r.impulse += rows;
      if (sim.ledger.enabled && ranks_->root()) book_body(sim, r, r.pred, free, r.q);
    }
  }

  /// u(x_I) at node n of rigid field f, with the body's current motion.
  void velocity(int f, size_t n, double (&u)[D]) const {
    velocity(bodies_[size_t(of_field_[size_t(f)])], n, u);
  }

  /// Step 1 (the header) from the fields' records (S per node, nodes per field) and the centre
  /// record's held velocities.
  void predict(const Simulation<D>& sim, const double* records, const double* centre, double dt) {
    for (Rigid& r : bodies_) {
      const double* rec = records + size_t(r.field) * nodes_ * S;
      r.start = momentum_motion(r, rec);
      typename Dofs::Vector force = Dofs::Vector::Zero();
      for (size_t n : r.nodes) {
        if (owned(n)) force += map_at(r, n).transpose() * Column(rec + n * S + kForce);
        std::fill_n(impulse_.begin() + long((size_t(r.field) * nodes_ + n) * D), D, 0.0);
        for (int f = 0; f < fields_; ++f) bond_[(size_t(f) * nodes_ + n) * kBond] = 0;
      }
      ranks_->sum(force.data(), Dofs::Q);
      collect_rows(sim, r, rec, centre);
      r.free = r.start + dt * Dofs::solve(r.metric, force);
      r.q = r.rows.constrained(r.free, r.metric, r.impulse);
    }
  }

  /// Step 4 (the header) on the fields' records.
  void correct(Simulation<D>& sim, double* records, double dt) {
    const HeldComponents& held = sim.held(0);
    for (Rigid& r : bodies_) {
      // The exchange's impulses beyond those that brought the bound momentum to r.q.
      typename Dofs::Vector impulse = Dofs::Vector::Zero();
      const double* imp = impulse_.data() + size_t(r.field) * nodes_ * D;
      const bool bound = !r.bound.isZero();
      for (size_t n : r.nodes) {
        if (!owned(n)) continue;
        const typename Dofs::Map g = map_at(r, n);
        impulse += g.transpose() * Column(imp + n * D);
        if (!bound) continue;
        const Eigen::Matrix<double, D, 1> u = g * r.q;
        for (int f = 0; f < fields_; ++f) {
          const Eigen::Matrix<double, D, D> mp = bound_mass(r, records, held, f, n);
          if (!mp.isZero()) impulse -= g.transpose() * mp * (Column(bond(f, n) + 2 + D) - u);
        }
      }
      ranks_->sum(impulse.data(), Dofs::Q);
      const typename Dofs::Vector met = r.q + Dofs::solve(r.joined, impulse);
      Eigen::VectorXd again;
      const typename Dofs::Vector q = r.rows.constrained(met, r.joined, again);
      double moment[Dofs::Q - D + 1] = {};
      report_row_forces(sim, r, r.impulse + again, dt, moment);
      if (sim.ledger.enabled && ranks_->root()) {
        // The rows' impulses of the prediction, at the mean of the velocities before and after.
        const typename Dofs::Vector rows = r.metric * (r.pred - r.free);
        sim.ledger.add_boundary_work(0.5 * rows.dot(r.free + r.pred));
        book_body(sim, r, r.q, met, q);
      }
      if (bound) move_bound_fields(sim, r, records, held, q - r.q, dt);
      double centre[D];  // after the step: the particles move with u(x_p), sum m_p r_p = 0
      for (int d = 0; d < D; ++d) centre[d] = r.centre[d] + dt * q(d);
      sim.rigid_records.record(r.condition, r.centre, centre, q.data() + D, moment, dt);
      r.q = q;
      write_nodes(r, records + size_t(r.field) * nodes_ * S, dt);
    }
  }

  /// Each rigid field's velocities u(x_I) in `velocities` (D per node, nodes per field): with
  /// the step's motion, or (`at_start`, USF before the update) the motion its momenta in
  /// `records` carry.
  void set_velocities(const double* records, double* velocities, bool at_start) {
    for (Rigid& r : bodies_) {
      if (at_start) r.q = momentum_motion(r, records + size_t(r.field) * nodes_ * S);
      double* vel = velocities + size_t(r.field) * nodes_ * D;
      for (size_t n : r.nodes) {
        double u[D];
        velocity(r, n, u);
        std::copy(u, u + D, vel + n * D);
      }
    }
  }

 private:
  using Dofs = RigidDofs<D>;
  using Column = Eigen::Map<const Eigen::Matrix<double, D, 1>>;
  static constexpr size_t kPrescribed = ~size_t(0);      // Rigid::row_node of a prescribed row
  static constexpr size_t kOtherRank = kPrescribed - 1;  // of a row another rank's node adds

  /// A body that moves rigidly in this step: its condition, field, mass, centre of mass and
  /// metric diag(M, J) (its particles at x^n), its nodes (mass > 0), the rows that constrain it
  /// (the velocities they impose, each one's node or kPrescribed and component, their impulse
  /// shares), its motion at t^n, after its own forces (`free`), and the motion it meets the
  /// other fields with, then the step's (`q`).
  struct Rigid {
    const Boundary<D>* condition = nullptr;
    const RigidMotion<D>* motion = nullptr;
    int field = 0;
    double mass = 0;
    double centre[D] = {};
    typename Dofs::Matrix metric = Dofs::Matrix::Zero();
    std::vector<size_t> nodes;
    RigidRows<D> rows;
    Eigen::VectorXd impulse;
    std::vector<size_t> row_node;
    std::vector<int> row_component;
    typename Dofs::Vector start = Dofs::Vector::Zero(), free = start, pred = start, q = start;
    typename Dofs::Matrix bound = Dofs::Matrix::Zero(), joined = bound;  // K, M_q + K
  };

  const Grid<D>* grid_ = nullptr;
  Ranks<D>* ranks_ = nullptr;
  std::vector<uint8_t> owned_;  // per node under mpirun: this rank owns it (empty serially)
  int fields_ = 0;
  size_t nodes_ = 0;
  std::vector<int> field_of_body_;
  std::vector<Rigid> bodies_;
  std::vector<int> of_field_;        // per field: its entry in bodies_, or -1
  std::vector<uint8_t> rigid_body_;  // per body: moves rigidly in this step
  std::vector<double> impulse_;      // fields * nodes * D
  std::vector<double> bond_;         // fields * nodes * kBond

  /// Mass, centre of mass and metric sum_p m_p G^T G (M on V; J = sum m (|r|^2 I - r r^T) on
  /// omega) of each body from its particles.
  void measure(const Simulation<D>& sim) {
    for_each_particle(sim, [](Rigid& r, double m, const double(&x)[D]) {
      r.mass += m;
      for (int d = 0; d < D; ++d) r.centre[d] += m * x[d];
    });
    std::vector<double> sums;
    for (Rigid& r : bodies_)
      sums.insert(sums.end(), {r.mass}), sums.insert(sums.end(), r.centre, r.centre + D);
    ranks_->sum(sums.data(), int(sums.size()));
    for (size_t k = 0; k < bodies_.size(); ++k) {
      Rigid& r = bodies_[k];
      r.mass = sums[k * (D + 1)];
      for (int d = 0; d < D; ++d)
        r.centre[d] = r.mass > 0 ? sums[k * (D + 1) + 1 + size_t(d)] / r.mass : 0.0;
    }
    for_each_particle(sim, [](Rigid& r, double m, const double(&x)[D]) {
      double rel[D];
      for (int d = 0; d < D; ++d) rel[d] = x[d] - r.centre[d];
      const auto g = Dofs::velocity_map(rel);
      r.metric += m * g.transpose() * g;
    });
    for (Rigid& r : bodies_) ranks_->sum(r.metric.data(), Dofs::Q * Dofs::Q);
  }
  /// Whether this rank counts node n in sums over the grid (each node on one rank).
  bool owned(size_t n) const { return owned_.empty() || owned_[n]; }
  /// A body whose particles have all left (a sink) moves no more: it is dropped.
  void drop_empty_bodies() {
    for (size_t k = bodies_.size(); k-- > 0;)
      if (!(bodies_[k].mass > 0)) {
        of_field_[size_t(bodies_[k].field)] = -1;
        rigid_body_[size_t(bodies_[k].motion->rigid_body())] = 0;
        bodies_.erase(bodies_.begin() + long(k));
      }
    for (size_t k = 0; k < bodies_.size(); ++k) of_field_[size_t(bodies_[k].field)] = int(k);
  }
  template <class F>
  void for_each_particle(const Simulation<D>& sim, F&& f) {
    for (const auto& set : sim.sets) {
      const Particles<D>& P = set.particles;
      for (size_t i = 0; i < P.size(); ++i) {
        if (!rigid_body_[P.body[i]]) continue;
        double x[D];
        for (int d = 0; d < D; ++d) x[d] = P.col(P.position, d)[i];
        const int field = field_of_body_[P.body[i]];
        f(bodies_[size_t(of_field_[size_t(field)])], P.col(P.mass)[i], x);
      }
    }
  }
  void velocity(const Rigid& r, size_t n, double (&u)[D]) const {
    const Eigen::Matrix<double, D, 1> v = map_at(r, n) * r.q;
    for (int d = 0; d < D; ++d) u[d] = v(d);
  }
  /// G(x_I - x_c) at node n of body r.
  typename Dofs::Map map_at(const Rigid& r, size_t n) const {
    double rel[D];
    for (int d = 0; d < D; ++d) rel[d] = grid_->node_coord(n, d) - r.centre[d];
    return Dofs::velocity_map(rel);
  }
  /// The motion r's nodal momenta carry (M_q q = sum G^T p); its nodes (mass > 0) found anew.
  typename Dofs::Vector momentum_motion(Rigid& r, const double* rec) const {
    typename Dofs::Vector sum = Dofs::Vector::Zero();
    r.nodes.clear();
    for (size_t n = 0; n < nodes_; ++n) {
      if (!(rec[n * S + kMass] > 0)) continue;
      r.nodes.push_back(n);
      if (owned(n)) sum += map_at(r, n).transpose() * Column(rec + n * S + kMomentum);
    }
    ranks_->sum(sum.data(), Dofs::Q);
    return Dofs::solve(r.metric, sum);
  }
  /// r's rows: its prescribed components, then the components the conditions hold at its
  /// nodes with mass above the tolerance (at the centre's velocity there) that are not
  /// prescribed, in its free components only. A prescribed component thus takes the whole
  /// force along it (a footing pushed down beside a held wall: the wall takes none of the
  /// vertical load; a sled pushed along a fixed base: the base holds it up, not back); where
  /// a symmetry plane should also keep a prescribed body from turning, give it
  /// `rotation: fixed`.
  void collect_rows(const Simulation<D>& sim, Rigid& r, const double* rec, const double* centre) {
    const HeldComponents& held = sim.held(0);
    std::vector<typename Dofs::Vector> rows;
    std::vector<double> values;
    r.row_node.clear();
    r.row_component.clear();
    auto add = [&](const typename Dofs::Vector& row, double value, size_t node, int component) {
      rows.push_back(row);
      values.push_back(value);
      r.row_node.push_back(node);
      r.row_component.push_back(component);
    };
    typename Dofs::Vector prescribed;
    const unsigned mask = r.motion->prescribed(sim.time - sim.loads_start, sim.dt, prescribed);
    for (int k = 0; k < Dofs::Q; ++k)
      if ((mask >> k) & 1) add(Dofs::Vector::Unit(k), prescribed(k), kPrescribed, k);
    for (size_t n : r.nodes) {
      if (!(rec[n * S + kMass] > sim.mass_tolerance) || !owned(n)) continue;
      for (int d = 0; d < D; ++d) {
        if (!held.held(n, d)) continue;
        if ((mask >> d) & 1) continue;  // the prescribed velocity wins along d
        typename Dofs::Vector row = map_at(r, n).row(d).transpose();
        double value = centre[n * S + kMomentum + size_t(d)];
        for (int k = 0; k < Dofs::Q; ++k)
          if ((mask >> k) & 1) value -= row(k) * prescribed(k), row(k) = 0;
        if (row.squaredNorm() > 0) add(row, value, n, d);
      }
    }
    if (ranks_->distributed()) gather_rows(r, rows, values);
    Eigen::MatrixXd a(long(rows.size()), Dofs::Q);
    Eigen::VectorXd b(long(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) {
      a.row(long(i)) = rows[i].transpose();
      b(long(i)) = values[i];
    }
    r.rows.set(a, b);
  }
  /// Under mpirun: every rank's held rows after the prescribed ones, in rank order; the other
  /// ranks' rows are marked kOtherRank.
  void gather_rows(Rigid& r, std::vector<typename Dofs::Vector>& rows,
                   std::vector<double>& values) const {
    constexpr int W = Dofs::Q + 2;  // the row, its value, its component
    const size_t first = size_t(std::count(r.row_node.begin(), r.row_node.end(), kPrescribed));
    std::vector<double> mine;
    for (size_t i = first; i < rows.size(); ++i) {
      mine.insert(mine.end(), rows[i].data(), rows[i].data() + Dofs::Q);
      mine.insert(mine.end(), {values[i], double(r.row_component[i])});
    }
    const std::vector<double> counts = ranks_->all_gather({double(rows.size() - first)});
    const std::vector<double> all = ranks_->all_gather(mine);
    size_t before = 0;
    for (int k = 0; k < ranks_->rank(); ++k) before += size_t(counts[size_t(k)]);
    const std::vector<size_t> nodes(r.row_node.begin() + long(first), r.row_node.end());
    rows.resize(first), values.resize(first);
    r.row_node.resize(first), r.row_component.resize(first);
    for (size_t i = 0; i * W < all.size(); ++i) {
      const double* row = all.data() + i * W;
      rows.push_back(Eigen::Map<const typename Dofs::Vector>(row));
      values.push_back(row[Dofs::Q]);
      const bool own = i >= before && i - before < nodes.size();
      r.row_node.push_back(own ? nodes[i - before] : kOtherRank);
      r.row_component.push_back(int(row[Dofs::Q + 1]));
    }
  }
  /// The rows' impulses x_i (per row, along it) as forces x_i / dt: at a held node, in its
  /// component, to the condition credited with the node (by the rank that owns it); the
  /// prescribed translation components' to r's condition (by rank 0); the prescribed rotation
  /// components' moment about the centre into `moment`.
  void report_row_forces(Simulation<D>& sim, const Rigid& r, const Eigen::VectorXd& impulse,
                         double dt, double* moment) const {
    double prescribed[D] = {};
    for (long i = 0; i < impulse.size(); ++i) {
      const size_t n = r.row_node[size_t(i)];
      const int k = r.row_component[size_t(i)];
      if (n == kPrescribed) {
        if (k < D)
          prescribed[k] += impulse(i) / dt;
        else
          moment[k - D] += impulse(i) / dt;
        continue;
      }
      if (n == kOtherRank) continue;
      double f[D] = {};
      f[k] = impulse(i) / dt;
      sim.reactions.add_node_force(n, f);
    }
    if (ranks_->root()) sim.reactions.add_force(r.condition, prescribed);
  }
  const double* bond(int f, size_t n) const {
    return bond_.data() + (size_t(f) * nodes_ + n) * kBond;
  }
  /// m_f P_f at node n for a field f bound to r there (bonds()): P = I stuck, n n^T sliding,
  /// without the components a condition holds (the exchange gives them back to the centre);
  /// zero where f is not bound to r.
  Eigen::Matrix<double, D, D> bound_mass(const Rigid& r, const double* records,
                                         const HeldComponents& held, int f, size_t n) const {
    Eigen::Matrix<double, D, D> p = Eigen::Matrix<double, D, D>::Zero();
    const double* b = bond(f, n);
    if (f == r.field || int(b[0]) != r.field + 1) return p;
    if (b[1] > 0)
      p.setIdentity();
    else
      p = Column(b + 2) * Column(b + 2).transpose();
    for (int d = 0; d < D; ++d)
      if (held.held(n, d)) p.row(d).setZero(), p.col(d).setZero();
    return records[(size_t(f) * nodes_ + n) * S + kMass] * p;
  }
  /// The fields bound to r follow its change of motion dq: v_f += P_f G dq at each node (the
  /// acceleration with it); the change of their kinetic energy goes to the contact's ledger.
  void move_bound_fields(Simulation<D>& sim, const Rigid& r, double* records,
                         const HeldComponents& held, const typename Dofs::Vector& dq,
                         double dt) const {
    for (size_t n : r.nodes) {
      const Eigen::Matrix<double, D, 1> du = map_at(r, n) * dq;
      for (int f = 0; f < fields_; ++f) {
        double* x = records + (size_t(f) * nodes_ + n) * S;
        const Eigen::Matrix<double, D, D> mp = bound_mass(r, records, held, f, n);
        if (mp.isZero()) continue;
        const Eigen::Matrix<double, D, 1> dv = mp * du / x[kMass];
        double work = 0;
        for (int d = 0; d < D; ++d) {
          work += x[kMass] * dv(d) * (x[kMomentum + d] + 0.5 * dv(d));
          x[kMomentum + d] += dv(d);
          x[kForce + d] += dv(d) / dt;
        }
        if (sim.ledger.enabled) sim.ledger.add_contact(n, -work);
      }
    }
  }
  /// The body's change of kinetic energy from q0 over q1 (the contact's impulse) to q2 (the
  /// rows'), each impulse at the mean of the velocities before and after it.
  static void book_body(Simulation<D>& sim, const Rigid& r, const typename Dofs::Vector& q0,
                        const typename Dofs::Vector& q1, const typename Dofs::Vector& q2) {
    const typename Dofs::Vector contact = r.metric * (q1 - q0), rows = r.metric * (q2 - q1);
    sim.ledger.add_contact_total(-0.5 * contact.dot(q0 + q1));
    sim.ledger.add_boundary_work(0.5 * rows.dot(q1 + q2));
  }
  /// r's nodes get u(x_I) in the momentum slot and (u - p / m) / dt in the force slot.
  void write_nodes(const Rigid& r, double* rec, double dt) const {
    for (size_t n : r.nodes) {
      double u[D];
      velocity(r, n, u);
      double* x = rec + n * S;
      for (int d = 0; d < D; ++d) {
        x[kForce + d] = (u[d] - x[kMomentum + d] / x[kMass]) / dt;
        x[kMomentum + d] = u[d];
      }
    }
  }
};

}  // namespace loam
