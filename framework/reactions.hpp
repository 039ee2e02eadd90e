#pragma once
// The reaction of each mechanical boundary condition: the force it applies on the model in a
// step, per phase, measured where it acts, in the grid update (Simulation::constrain_update).
// A condition changes the nodal velocity v^{n+1} = v^n + dt a of its nodes and keeps the
// acceleration consistent with it, so the force it adds is
//   R = sum over its nodes of m (a_after - a_before) = sum m (v_held - v_free) / dt,
// the momentum it takes or gives per unit time: a fixed base under a column at rest carries
// the column's weight, a footing pushed by prescribed_velocity the soil's resistance (with the
// sign of the force on the model: a base holding a column up reports +W along the vertical).
// It covers the kinematic pass (holds, dashpots, unilateral contact) and the Coulomb pass
// (friction). Local damping changes the nodal forces before the conditions act (Cundall's
// f -= alpha |f| sign(v), with v a node's round-off velocity on a held face): that change is
// no force of the model's, so at the components a condition changes the damping's force is
// added back, and the reaction is the force the model's stresses, weight and loads put on
// the support (R = -f there), whatever the damping. Where several conditions share a node (an edge,
// a corner), the change is credited to the one that makes it, in the config's order; their sum is
// the node's whole reaction. Under mpirun each rank sums the nodes it owns, the step's values are
// summed over the ranks. Hydraulic conditions (a force on the water, Boundary::add_forces) and
// periodic faces report none.
#include <algorithm>
#include <array>
#include <limits>
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
    entries_[b] = Entry{slot, {}, {}, false};
    step_.assign(names_.size() * kValues, 0.0);
    low_.assign(step_.size(), std::numeric_limits<double>::infinity());
    high_.assign(step_.size(), -std::numeric_limits<double>::infinity());
  }
  const std::vector<std::string>& names() const { return names_; }
  bool empty() const { return names_.empty(); }

  /// Run `act` (b's part of the grid update u) and add the force it applied at b's nodes.
  template <class F>
  void measure(const Boundary<D>& b, const GridUpdate& u, const Grid<D>& grid,
               const Ranks<D>& ranks, F&& act) {
    const auto it = entries_.find(&b);
    if (it == entries_.end()) return act();
    Entry& e = it->second;
    if (!e.ready || b.reaction_nodes_move()) owned_nodes(b, grid, ranks, e);
    before_.resize(e.nodes.size() * size_t(kValues));
    for (int k = 0; k < u.count; ++k)
      for (size_t j = 0; j < e.nodes.size(); ++j)
        for (int d = 0; d < D; ++d)
          before_[(j * 2 + size_t(k)) * D + size_t(d)] =
              u.phases[size_t(k)].acceleration.at(e.nodes[j], d);
    act();
    double* r = step_.data() + size_t(e.slot) * kValues;
    for (int k = 0; k < u.count; ++k)
      for (size_t j = 0; j < e.nodes.size(); ++j) {
        const PhaseUpdate& ph = u.phases[size_t(k)];
        const double m = ph.mass.at(e.nodes[j], 0);
        for (int d = 0; d < D; ++d) {
          const double da =
              ph.acceleration.at(e.nodes[j], d) - before_[(j * 2 + size_t(k)) * D + size_t(d)];
          r[k * D + d] += m * da;
          if (k == 0 && damped_ && da != 0) r[d] += e.damping[j * D + size_t(d)];
        }
      }
  }

  /// Local damping acts on the nodal forces of phase 0 (the only phase or the skeleton):
  /// the forces at every reporting node before it, then after it (their difference is the
  /// damping's force, left out of the reactions).
  void before_damping(const NodalVector& force, const Grid<D>& grid, const Ranks<D>& ranks) {
    for (auto& [b, e] : entries_) {
      if (!e.ready || b->reaction_nodes_move()) owned_nodes(*b, grid, ranks, e);
      e.damping.resize(e.nodes.size() * D);
      for (size_t j = 0; j < e.nodes.size(); ++j)
        for (int d = 0; d < D; ++d) e.damping[j * D + size_t(d)] = -force.at(e.nodes[j], d);
    }
  }
  void after_damping(const NodalVector& force) {
    for (auto& [b, e] : entries_)
      for (size_t j = 0; j < e.nodes.size(); ++j)
        for (int d = 0; d < D; ++d) e.damping[j * D + size_t(d)] += force.at(e.nodes[j], d);
    damped_ = true;
  }

  /// A new step: no force yet.
  void begin_step() {
    std::fill(step_.begin(), step_.end(), 0.0);
    damped_ = false;
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
  struct Entry {
    int slot = -1;
    std::vector<size_t> nodes;    // the condition's nodes this rank owns
    std::vector<double> damping;  // per node and component: the damping's force of the step
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
  bool damped_ = false;  // damping acted in this step (the entries' damping is its force)
};

}  // namespace loam
