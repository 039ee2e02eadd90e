#pragma once
// The reaction of each mechanical boundary condition: the force it applies on the model in a
// step, per phase. The conditions change the nodal velocity v^{n+1} = v^n + dt a of their nodes
// and keep the acceleration consistent with it, so the force on a node is m (a_after -
// a_before), taken over the whole constraint stage of the grid update (Simulation::
// constrain_update): the kinematic and Coulomb passes, the hydraulic conditions on the water
// (a drained face that releases the water a fixed face held leaves no water force; an
// impermeable one that holds it adds one) and a two-phase scheme's re-solve of a free phase
// against a held one (the drag the held phase then carries). Each node is credited to the first
// condition in the list that names it (list a wall before the base to give it the corner).
// A fixed base under a column at rest carries its weight, a footing pushed by a prescribed
// velocity the soil's resistance (the sign is the force on the model: a base holding a column up
// reports +W along the vertical). Face forces a condition adds itself (Boundary::add_forces, an
// absorbing face's free-field reaction) are measured around that call. Local damping changes
// the nodal forces before the conditions act (Cundall's f -= alpha |f| sign(v), v a held node's
// round-off velocity): at a component held at the end its force is added back, so the reaction
// is what the stresses, weight and loads put on the support, whatever the damping. Under mpirun
// each rank sums the nodes it owns and the step's values are summed over the ranks.
#include <algorithm>
#include <array>
#include <limits>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "framework/boundary.hpp"
#include "framework/grid.hpp"
#include "framework/ranks.hpp"

namespace loam {

template <int D>
class Reactions {
 public:
  static constexpr int kValues = 2 * D;  // per column: phase 0 (solid or only), phase 1 (water)

  /// Report condition b's reaction under `name`: conditions of one name (the same face in two
  /// stages) share a column.
  void add(const Boundary<D>* b, const std::string& name) {
    if (!b->reaction_nodes()) return;
    const auto it = std::find(names_.begin(), names_.end(), name);
    const int slot = int(it - names_.begin());
    if (it == names_.end()) names_.push_back(name);
    entries_[b] = Entry{slot, {}, false};
    step_.assign(names_.size() * kValues, 0.0);
    low_.assign(step_.size(), std::numeric_limits<double>::infinity());
    high_.assign(step_.size(), -std::numeric_limits<double>::infinity());
  }
  const std::vector<std::string>& names() const { return names_; }
  bool empty() const { return names_.empty(); }

  /// Before the boundary passes of a step: the nodes each active condition reports (a node
  /// named by several conditions goes to the first in the list) and their accelerations.
  void begin_update(const std::vector<std::unique_ptr<Boundary<D>>>& active, const GridUpdate& u,
                    const Grid<D>& grid, const Ranks<D>& ranks) {
    if (owner_.size() != grid.num_nodes) owner_.assign(grid.num_nodes, -1);
    for (size_t n : claimed_) owner_[n] = -1;
    claimed_.clear();
    for (const auto& b : active) {
      const auto it = entries_.find(b.get());
      if (it == entries_.end()) continue;
      Entry& e = it->second;
      if (!e.ready || b->reaction_nodes_move()) owned_nodes(*b, grid, ranks, e);
      for (size_t n : e.nodes)
        if (owner_[n] < 0) owner_[n] = e.slot, claimed_.push_back(n);
    }
    before_.resize(claimed_.size() * size_t(kValues));
    for (int k = 0; k < u.count; ++k)
      for (size_t j = 0; j < claimed_.size(); ++j)
        for (int d = 0; d < D; ++d)
          before_[(j * 2 + size_t(k)) * D + size_t(d)] =
              u.phases[size_t(k)].acceleration.at(claimed_[j], d);
  }
  /// After every pass (hydraulic conditions and a two-phase scheme's re-solve of a free phase
  /// against a held one included): m (a_after - a_before) per node and phase to its
  /// condition, and the damping's force at the components held at the end.
  void end_update(const GridUpdate& u) {
    for (int k = 0; k < u.count; ++k)
      for (size_t j = 0; j < claimed_.size(); ++j) {
        const size_t n = claimed_[j];
        const PhaseUpdate& ph = u.phases[size_t(k)];
        double* r = step_.data() + size_t(owner_[n]) * kValues + size_t(k * D);
        for (int d = 0; d < D; ++d) {
          const double da = ph.acceleration.at(n, d) - before_[(j * 2 + size_t(k)) * D + size_t(d)];
          r[d] += ph.mass.at(n, 0) * da;
          const bool held = u.held[size_t(k)] && u.held[size_t(k)]->held(n, d);
          if (damped_[k] && held && da != 0) r[d] += damping_of(k)[n * D + size_t(d)];
        }
      }
  }
  /// A force at node n (phase 0) that the condition credited with n in this step's update
  /// applies beyond the nodal mass it measured (a rigid body held there,
  /// framework/contact_fields.hpp); none if no reporting condition holds n.
  void add_node_force(size_t n, const double (&force)[D]) {
    if (n < owner_.size() && owner_[n] >= 0) add_to_slot(owner_[n], force);
  }

  /// Face forces (Boundary::add_forces, e.g. an absorbing face's free-field reaction): the
  /// change `act` makes at b's nodes, the mixture (or only) force to phase 0, the water's to 1.
  template <class F>
  void measure_forces(const Boundary<D>& b, const GridForces& f, const Grid<D>& grid,
                      const Ranks<D>& ranks, F&& act) {
    const auto it = entries_.find(&b);
    if (it == entries_.end()) return act();
    Entry& e = it->second;
    if (!e.ready || b.reaction_nodes_move()) owned_nodes(b, grid, ranks, e);
    const NodalVector* v[2] = {&f.mixture, &f.water};
    before_.resize(e.nodes.size() * size_t(kValues));
    for (int k = 0; k < f.count; ++k)
      for (size_t j = 0; j < e.nodes.size(); ++j)
        for (int d = 0; d < D; ++d)
          before_[(j * 2 + size_t(k)) * D + size_t(d)] = v[k]->at(e.nodes[j], d);
    act();
    double* r = step_.data() + size_t(e.slot) * kValues;
    for (int k = 0; k < f.count; ++k)
      for (size_t j = 0; j < e.nodes.size(); ++j)
        for (int d = 0; d < D; ++d)
          r[k * D + d] += v[k]->at(e.nodes[j], d) - before_[(j * 2 + size_t(k)) * D + size_t(d)];
  }

  /// A force condition b measured itself in this step (a rigid body in contact: the force its
  /// prescribed motion and the faces it touches apply to it), phase 0.
  void add_force(const Boundary<D>* b, const double (&force)[D]) {
    const auto it = entries_.find(b);
    if (it != entries_.end()) add_to_slot(it->second.slot, force);
  }

  /// Local damping acts on the nodal forces of a momentum balance (the liquid's too where the
  /// damping damps it): the forces at every reporting node before it, then after it (their
  /// difference is the damping's force, left out of the reactions where a condition holds the
  /// component).
  void before_damping(const NodalVector& force, const Grid<D>& grid, const Ranks<D>& ranks,
                      MomentumBalance balance) {
    if (damping_.size() != 2 * grid.num_nodes * D) damping_.assign(2 * grid.num_nodes * D, 0.0);
    if (owner_.size() != grid.num_nodes) owner_.assign(grid.num_nodes, -1);
    damped_nodes_.clear();
    for (auto& [b, e] : entries_) {
      if (!e.ready || b->reaction_nodes_move()) owned_nodes(*b, grid, ranks, e);
      for (size_t n : e.nodes)
        if (owner_[n] != -2) owner_[n] = -2, damped_nodes_.push_back(n);  // each node once
    }
    double* damping = damping_of(int(balance));
    for (size_t n : damped_nodes_) {
      owner_[n] = -1;
      for (int d = 0; d < D; ++d) damping[n * D + size_t(d)] = -force.at(n, d);
    }
  }
  void after_damping(const NodalVector& force, MomentumBalance balance) {
    double* damping = damping_of(int(balance));
    for (size_t n : damped_nodes_)
      for (int d = 0; d < D; ++d) damping[n * D + size_t(d)] += force.at(n, d);
    damped_[int(balance)] = true;
  }

  /// A new step: no force yet.
  void begin_step() {
    std::fill(step_.begin(), step_.end(), 0.0);
    damped_[0] = damped_[1] = false;
  }
  /// The step's forces complete over the ranks, and the extremes of the run so far.
  void end_step(const Ranks<D>& ranks) {
    if (names_.empty()) return;
    if (ranks.distributed()) ranks.sum(step_.data(), int(step_.size()));
    for (size_t i = 0; i < step_.size(); ++i) {
      low_[i] = std::min(low_[i], step_[i]);
      high_[i] = std::max(high_[i], step_[i]);
    }
  }
  /// Column `slot`'s force of the last step: D values of phase 0, then D of phase 1.
  const double* force(size_t slot) const { return step_.data() + slot * kValues; }
  const double* lowest(size_t slot) const { return low_.data() + slot * kValues; }
  const double* highest(size_t slot) const { return high_.data() + slot * kValues; }

  /// Checkpoints: the last step's forces and the extremes.
  std::vector<double> state() const {
    std::vector<double> s = step_;
    s.insert(s.end(), low_.begin(), low_.end());
    s.insert(s.end(), high_.begin(), high_.end());
    return s;
  }
  void restore(const std::vector<double>& s) {
    const size_t n = step_.size();
    if (s.size() != 3 * n) return;
    std::copy(s.begin(), s.begin() + long(n), step_.begin());
    std::copy(s.begin() + long(n), s.begin() + long(2 * n), low_.begin());
    std::copy(s.begin() + long(2 * n), s.end(), high_.begin());
  }

 private:
  /// Column `slot`'s phase-0 force of this step += force.
  void add_to_slot(int slot, const double (&force)[D]) {
    double* r = step_.data() + size_t(slot) * kValues;
    for (int d = 0; d < D; ++d) r[d] += force[d];
  }
  struct Entry {
    int slot = -1;
    std::vector<size_t> nodes;  // the condition's nodes this rank owns
    bool ready = false;
  };
  /// The nodes of b this rank owns (each node counted on one rank), once its nodes are set up.
  static void owned_nodes(const Boundary<D>& b, const Grid<D>& grid, const Ranks<D>& ranks,
                          Entry& e) {
    e.nodes.clear();
    for (size_t n : *b.reaction_nodes())
      if (ranks.owns_node(grid, grid.node_ijk(n))) e.nodes.push_back(n);
    e.ready = true;
  }
  std::vector<std::string> names_;
  std::unordered_map<const Boundary<D>*, Entry> entries_;
  std::vector<double> step_, low_, high_, before_;
  std::vector<int> owner_;       // per grid node: the column it is credited to this step, or -1
  std::vector<size_t> claimed_;  // the nodes credited this step
  std::vector<double>
      damping_;  // per phase, grid node and component: the damping's force (reporting nodes)
  std::vector<size_t> damped_nodes_;  // the reporting nodes, each once, where damping_ is set
  bool damped_[2] = {false, false};   // damping acted on the phase in this step

  /// Phase k's part of damping_ (each phase has half of it).
  double* damping_of(int k) { return damping_.data() + size_t(k) * (damping_.size() / 2); }
};

}  // namespace loam
