#pragma once
// The velocity fields of rigid bodies under contact (docs/contact.md, framework/rigid_motion.hpp).
// A condition whose rigid_motion() names a body on a field of its own makes that field rigid in
// the step: the field stays out of the centre record (framework/contact_fields.hpp), and
//  1. predict: the body's mass, centre and metric come from its particles at x^n; its nodal
//     momenta and forces (gravity, particle loads; the internal forces add none) give its motion
//     after its own forces, projected on its rows (prescribed components; components a condition
//     holds at a node it reaches, at that node's held velocity);
//  2. the contact exchange meets it as a body of infinite mass at that motion, and records the
//     impulse each of the other fields takes from it per node (impulses());
//  3. correct: those impulses, summed as momentum and angular momentum, move it; the rows are
//     imposed again; its nodes get u(x_I) and the acceleration (u - p / m) / dt. The rows'
//     forces are reactions: a held node's to the condition credited with that node, the
//     prescribed components' to the body's condition; their work and the impulses' go to the
//     energy ledger.
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

  /// `fields` velocity fields of num_nodes nodes; field_of_body: each body's field.
  void setup(const Grid<D>& grid, int fields, const std::vector<int>& field_of_body) {
    grid_ = &grid;
    fields_ = fields;
    nodes_ = grid.num_nodes;
    field_of_body_ = field_of_body;
    of_field_.assign(size_t(fields), -1);
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
        force += map_at(r, n).transpose() * Column(rec + n * S + kForce);
        std::fill_n(impulse_.begin() + long((size_t(r.field) * nodes_ + n) * D), D, 0.0);
      }
      collect_rows(sim, r, rec, centre);
      r.free = r.start + dt * Dofs::solve(r.metric, force);
      r.q = r.rows.constrained(r.free, r.metric, r.impulse);
    }
  }

  /// Step 3 (the header) on the fields' records.
  void correct(Simulation<D>& sim, double* records, double dt) {
    for (Rigid& r : bodies_) {
      typename Dofs::Vector impulse = Dofs::Vector::Zero();
      const double* imp = impulse_.data() + size_t(r.field) * nodes_ * D;
      for (size_t n : r.nodes) impulse += map_at(r, n).transpose() * Column(imp + n * D);
      const typename Dofs::Vector met = r.q + Dofs::solve(r.metric, impulse);
      Eigen::VectorXd again;
      const typename Dofs::Vector q = r.rows.constrained(met, r.metric, again);
      report_row_forces(sim, r, r.impulse + again, dt);
      if (sim.ledger.enabled && !r.nodes.empty()) {
        const typename Dofs::Vector before = r.metric * (r.q - r.free);  // the rows' impulses
        const typename Dofs::Vector after = r.metric * (q - met);
        // Each impulse's work at the mean of the velocities before and after it: the change
        // of the body's kinetic energy 1/2 q^T M_q q it makes.
        sim.ledger.add_contact(r.nodes.front(), -0.5 * impulse.dot(r.q + met));
        sim.ledger.add_boundary_work(0.5 * (before.dot(r.free + r.q) + after.dot(met + q)));
      }
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
  static constexpr size_t kPrescribed = ~size_t(0);  // Rigid::row_node of a prescribed row

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
    typename Dofs::Vector start = Dofs::Vector::Zero(), free = start, q = start;
  };

  const Grid<D>* grid_ = nullptr;
  int fields_ = 0;
  size_t nodes_ = 0;
  std::vector<int> field_of_body_;
  std::vector<Rigid> bodies_;
  std::vector<int> of_field_;        // per field: its entry in bodies_, or -1
  std::vector<uint8_t> rigid_body_;  // per body: moves rigidly in this step
  std::vector<double> impulse_;      // fields * nodes * D

  /// Mass, centre of mass and metric sum_p m_p G^T G (M on V; J = sum m (|r|^2 I - r r^T) on
  /// omega) of each body from its particles.
  void measure(const Simulation<D>& sim) {
    for_each_particle(sim, [](Rigid& r, double m, const double(&x)[D]) {
      r.mass += m;
      for (int d = 0; d < D; ++d) r.centre[d] += m * x[d];
    });
    for (Rigid& r : bodies_)
      for (int d = 0; d < D; ++d) r.centre[d] = r.mass > 0 ? r.centre[d] / r.mass : 0.0;
    for_each_particle(sim, [](Rigid& r, double m, const double(&x)[D]) {
      double rel[D];
      for (int d = 0; d < D; ++d) rel[d] = x[d] - r.centre[d];
      const auto g = Dofs::velocity_map(rel);
      r.metric += m * g.transpose() * g;
    });
  }
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
      sum += map_at(r, n).transpose() * Column(rec + n * S + kMomentum);
    }
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
    const unsigned mask = r.motion->prescribed(sim.time - sim.loads_start, prescribed);
    for (int k = 0; k < Dofs::Q; ++k)
      if ((mask >> k) & 1) add(Dofs::Vector::Unit(k), prescribed(k), kPrescribed, k);
    for (size_t n : r.nodes) {
      if (!(rec[n * S + kMass] > sim.mass_tolerance)) continue;
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
    Eigen::MatrixXd a(long(rows.size()), Dofs::Q);
    Eigen::VectorXd b(long(rows.size()));
    for (size_t i = 0; i < rows.size(); ++i) {
      a.row(long(i)) = rows[i].transpose();
      b(long(i)) = values[i];
    }
    r.rows.set(a, b);
  }
  /// The rows' impulses x_i (per row, along it) as forces x_i / dt: at a held node, in its
  /// component, to the condition credited with the node; the prescribed translation
  /// components' to r's condition.
  void report_row_forces(Simulation<D>& sim, const Rigid& r, const Eigen::VectorXd& impulse,
                         double dt) const {
    double prescribed[D] = {};
    for (long i = 0; i < impulse.size(); ++i) {
      const size_t n = r.row_node[size_t(i)];
      const int k = r.row_component[size_t(i)];
      if (n == kPrescribed) {
        if (k < D) prescribed[k] += impulse(i) / dt;
        continue;
      }
      double f[D] = {};
      f[k] = impulse(i) / dt;
      sim.reactions.add_node_force(n, f);
    }
    sim.reactions.add_force(r.condition, prescribed);
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
