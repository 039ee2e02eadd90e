#pragma once
// The energy balance of a run (history.csv): where the work done on the model went.
//
//   E_kin + E_stored + E_grav + D_material + D_damping + D_transfer + D_drag + D_contact
//     - W_loads - W_boundaries - E_carried - E_0 = balance
//
// Every term is summed since the run began (J; per unit thickness in 2D):
// - D_material, the stress work not stored: sum over steps and particles of V sigma : L dt with
//   the mean of the stresses before and after the material update, minus the change of the
//   stored strain energy. Plastic and viscous dissipation; a material that reports no strain
//   energy (Material::strain_energy NaN) counts all its stress work here.
// - D_damping, the work the damping forces take out of the grid's motion;
// - D_transfer, what the velocity transfer takes from the particles against a FLIP update:
//   1/2 m (|v^n + dt a|^2 - |v^{n+1}|^2) at each particle's grid-to-particle update, PIC's share
//   of a FLIP/PIC blend (Brackbill & Ruppel 1986); zero for FLIP;
// - W_loads: tractions, point loads, cavity pressure; W_boundaries: the conditions' constraint
//   stage and the face forces they add (absorbing);
// - D_drag, the two-phase drag's dissipation, Q |w - v|^2 dt per node at the implicit solve's
//   velocities (the pore water's pressure work ends there and in the stored p^2 n V / (2 K_w));
// - D_contact, minus the work of the contact forces between bodies on their own velocity fields
//   (framework/contact_fields.hpp): the normal impulses that stop an approach and friction;
// - E_carried: the energy of the particles created (sources, bodies a stage activates) less that
//   of the particles removed (sinks, deactivated bodies);
// - E_0 the energy at the start.
// A force recorded at the nodes (loads on the grid, damping, face forces) does work with the
// mean of the step's velocities (v^n + v^{n+1}) / 2 of the first phase (the skeleton), or with
// v^{n+1} at a component a condition holds (the condition's reaction, taken there, cancels it);
// a load on particles on their moves x^{n+1} - x^n. The balance is then the discrete
// work-energy theorem's residual: the internal forces' work at the nodes against the stress work
// at the particles, gravity's against the particles' fall, O(dt) per unit time.
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "framework/boundary.hpp"
#include "framework/energies.hpp"
#include "framework/grid.hpp"
#include "framework/particles.hpp"
#include "framework/ranks.hpp"
#include "framework/shape_function.hpp"

namespace loam {

/// sum_p V sigma : L over particles [b, b + count) of P, L in block layout (MaterialBatch):
/// the stress power of a block.
template <int D>
double block_stress_power(const Particles<D>& P, size_t b, int count, const double* L) {
  const double* V = P.col(P.volume) + b;
  double sum = 0;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      const double* s = P.col(P.stress, voigt_index(i, j)) + b;
      const double* l = L + size_t(i * D + j) * kBlock;
      for (int p = 0; p < count; ++p) sum += V[p] * s[p] * l[p];
    }
  return sum;
}

/// The balance's terms (J), as history.csv writes them.
struct EnergyBalance {
  double material = 0, damping = 0, transfer = 0, drag = 0, contact = 0;  // dissipations
  double loads = 0, boundaries = 0, carried = 0;  // work done on the model, energy brought in
  double balance = 0;
  /// The largest magnitude of the energies and terms, the balance's scale.
  double largest = 0;
};

/// The balance of the energies `now` against those at the start, with the ledger's totals
/// (a material without strain energy, NaN, stores none).
template <class Totals>
EnergyBalance energy_balance(const Energies& now, const Energies& start, const Totals& t) {
  auto stored = [](double w) { return std::isnan(w) ? 0.0 : w; };
  EnergyBalance b;
  b.material = t.stress_work - (stored(now.strain) - stored(start.strain) - t.carried_stored);
  b.damping = -t.damping;
  b.transfer = t.transfer;
  b.drag = t.drag;
  b.contact = t.contact;
  b.loads = t.loads;
  b.boundaries = t.boundaries;
  b.carried = t.carried_kinetic + t.carried_stored + t.carried_gravity;
  const double e_now = now.kinetic + stored(now.strain) + now.gravity;
  const double e_start = start.kinetic + stored(start.strain) + start.gravity;
  b.balance = e_now + b.material + b.damping + b.transfer + b.drag + b.contact - b.loads -
              b.boundaries - b.carried - e_start;
  for (double x : {now.kinetic, stored(now.strain), now.gravity - start.gravity, b.material,
                   b.damping, b.transfer, b.drag, b.contact, b.loads, b.boundaries, b.carried})
    b.largest = std::max(b.largest, std::abs(x));
  return b;
}

/// The nodal forces whose work the ledger records.
enum class NodalWork { kLoads, kDamping, kBoundaries };

template <int D>
class EnergyLedger {
 public:
  /// Work and energy flows since the run began.
  struct Totals {
    double stress_work = 0;  // sum V sigma : L dt (the materials' stress work)
    double transfer = 0;     // sum 1/2 m (|v_FLIP|^2 - |v^{n+1}|^2) at the particle updates
    double drag = 0;         // sum Q |w - v|^2 dt over the nodes (two-phase schemes)
    double contact = 0;      // minus the contact forces' work (contact between bodies)
    double damping = 0;      // the damping forces' work (<= 0)
    double loads = 0;        // tractions, point loads, cavity pressure
    double boundaries = 0;   // the conditions' constraint stage and face forces
    // created less removed particles: this rank's (global())
    double carried_kinetic = 0, carried_stored = 0, carried_gravity = 0;
  };
  Totals totals;
  /// Measured only when asked (output.energy_balance): the passes cost a few % of a step.
  bool enabled = false;

  /// The totals of the whole model (every rank calls it).
  Totals global(const Ranks<D>& ranks) const {
    Totals t = totals;
    double c[3] = {t.carried_kinetic, t.carried_stored, t.carried_gravity};
    if (ranks.distributed()) ranks.sum(c, 3);
    t.carried_kinetic = c[0], t.carried_stored = c[1], t.carried_gravity = c[2];
    return t;
  }

  /// A new step on `grid` with particle sets of `set_sizes` particles: no nodal force recorded,
  /// no block summed yet.
  void begin_step(const Grid<D>& grid, const Ranks<D>& ranks,
                  const std::vector<size_t>& set_sizes) {
    if (!enabled) return;
    num_nodes_ = grid.num_nodes;
    owned_nodes(grid, ranks);
    recorded_.fill(false);
    const size_t threads = size_t(std::max(omp_get_max_threads(), 1));
    if (per_thread_.size() < threads) per_thread_.assign(threads, Padded{});
    blocks_.resize(set_sizes.size());
    for (size_t s = 0; s < set_sizes.size(); ++s) blocks_[s].assign(set_sizes[s], BlockSums{});
  }
  /// The step's sums complete over the threads and the ranks (one message), into the totals;
  /// `particle_loads` the work of the loads on particles in this step (this rank's).
  template <class R>
  void end_step(const R& ranks, double particle_loads) {
    if (!enabled) return;
    double step[7] = {0, 0, node_work_[0] + particle_loads, node_work_[1], node_work_[2], 0, 0};
    for (const auto& set : blocks_)  // in block order: the same sum at any thread schedule
      for (const BlockSums& b : set) step[0] += b.stress, step[1] += b.transfer;
    for (auto& s : per_thread_) step[5] += s.drag, step[6] += s.contact, s = Padded{};
    if (ranks.distributed()) ranks.sum(step, 7);
    totals.stress_work += step[0];
    totals.transfer += step[1];
    totals.loads += step[2];
    totals.damping += step[3];
    totals.boundaries += step[4];
    totals.drag += step[5];
    totals.contact += step[6];
    node_work_.fill(0.0);
  }

  /// Stress work of the block of set `set` that begins at particle b, V sigma : L dt with sigma
  /// the mean of `before` and `after` (each sum_p V sigma : L over the block).
  void add_stress_work(size_t set, size_t b, double before, double after, double dt) {
    blocks_[set][b].stress += 0.5 * (before + after) * dt;
  }
  /// The drag's dissipation at node n in this step, by the calling thread (a node another rank
  /// owns is left to it; the nodes are shared out to the threads in a fixed order).
  void add_drag(size_t n, double dissipated) {
    if (enabled && (!distributed_ || owned_[n]))
      per_thread_[size_t(omp_get_thread_num())].drag += dissipated;
  }
  /// The contact forces' dissipation at node n in this step (as add_drag).
  void add_contact(size_t n, double dissipated) {
    if (enabled && (!distributed_ || owned_[n]))
      per_thread_[size_t(omp_get_thread_num())].contact += dissipated;
  }
  /// Contact work not tied to a node (a rigid body's, summed over its nodes); under mpirun
  /// one rank adds it.
  void add_contact_total(double dissipated) {
    if (enabled) per_thread_[size_t(omp_get_thread_num())].contact += dissipated;
  }
  /// Work the conditions did in this step that no nodal force records (a rigid body's
  /// constraints, framework/contact_fields.hpp).
  void add_boundary_work(double work) {
    if (enabled) node_work_[size_t(NodalWork::kBoundaries)] += work;
  }
  /// Kinetic energy the grid-to-particle update of the block of set `set` that begins at
  /// particle b took against FLIP.
  void add_transfer_loss(size_t set, size_t b, double loss) {
    if (enabled) blocks_[set][b].transfer += loss;
  }

  /// Runs `act` and records the change it makes to `force` (phase 0, every node) as a force of
  /// `kind`.
  template <class F>
  void record(NodalWork kind, const NodalVector& force, F&& act) {
    record_if(true, kind, force, act);
  }
  /// As record, where `adds` says whether `act` adds forces at all (one that joins nodes or
  /// refreshes its own state is not work done on the model).
  template <class F>
  void record_if(bool adds, NodalWork kind, const NodalVector& force, F&& act) {
    if (!enabled || !adds) return act();
    before_.resize(num_nodes_ * D);
    for (size_t n = 0; n < num_nodes_; ++n)
      for (int d = 0; d < D; ++d) before_[n * D + size_t(d)] = force.at(n, d);
    act();
    std::vector<double>& f = applied_[size_t(kind)];
    if (!recorded_[size_t(kind)]) f.assign(num_nodes_ * D, 0.0);
    recorded_[size_t(kind)] = true;
    for (size_t n = 0; n < num_nodes_; ++n)
      for (int d = 0; d < D; ++d)
        f[n * D + size_t(d)] += force.at(n, d) - before_[n * D + size_t(d)];
  }

  /// Before the constraint stage of the grid update: the velocities before the conditions and
  /// at the step's start, v^n = v - dt a; the recorded forces' power at v^n.
  void begin_update(const GridUpdate& u) {
    if (!enabled) return;
    free_.resize(size_t(u.count) * num_nodes_ * 2 * D);
    for (int k = 0; k < u.count; ++k)
      for_each_owned([&](size_t n) {
        const PhaseUpdate& ph = u.phases[size_t(k)];
        double* s = free_.data() + (size_t(k) * num_nodes_ + n) * 2 * D;
        for (int d = 0; d < D; ++d) {
          s[d] = ph.velocity.at(n, d);
          s[D + d] = s[d] - u.dt * ph.acceleration.at(n, d);
        }
      });
  }
  /// After the constraint stage: the conditions' work, their force m (a - a_free) (the
  /// reaction, framework/reactions.hpp) times the velocity v^{n+1} that moves the particles (a
  /// fixed node does none, a prescribed velocity its reaction times it, friction its force times
  /// the slip); the recorded forces' power at v^{n+1}.
  void end_update(const GridUpdate& u) {
    if (!enabled) return;
    double work = 0;
    for (int k = 0; k < u.count; ++k)
      for_each_owned([&](size_t n) {
        const PhaseUpdate& ph = u.phases[size_t(k)];
        const double m = ph.mass.at(n, 0);
        const double* s = free_.data() + (size_t(k) * num_nodes_ + n) * 2 * D;
        for (int d = 0; d < D; ++d) {
          const double v = ph.velocity.at(n, d);
          const double a_free = (s[d] - s[D + d]) / u.dt;
          work += u.dt * m * (ph.acceleration.at(n, d) - a_free) * v;
        }
      });
    node_work_[size_t(NodalWork::kBoundaries)] += work;
    recorded_work(u);
  }
  /// Checkpoints and strength-reduction trials: the totals.
  std::vector<double> state() const {
    const Totals& t = totals;
    return {t.stress_work,     t.transfer,       t.damping,         t.loads, t.boundaries,
            t.carried_kinetic, t.carried_stored, t.carried_gravity, t.drag,  t.contact};
  }
  void restore(const std::vector<double>& s) {
    if (s.size() != 9 && s.size() != 10) return;  // 9: written before contact
    Totals& t = totals;
    t.stress_work = s[0], t.transfer = s[1], t.damping = s[2], t.loads = s[3];
    t.boundaries = s[4], t.carried_kinetic = s[5], t.carried_stored = s[6];
    t.carried_gravity = s[7], t.drag = s[8];
    t.contact = s.size() > 9 ? s[9] : 0.0;
  }

 private:
  struct alignas(64) Padded {
    double drag = 0, contact = 0;
  };
  struct BlockSums {
    double stress = 0, transfer = 0;
  };
  /// Under mpirun each node is counted by the rank that owns it.
  void owned_nodes(const Grid<D>& grid, const Ranks<D>& ranks) {
    distributed_ = ranks.distributed();
    if (!distributed_ || owned_.size() == grid.num_nodes) return;
    owned_.resize(grid.num_nodes);
    for (size_t n = 0; n < grid.num_nodes; ++n)
      owned_[n] = ranks.owns_node(grid, grid.node_ijk(n)) ? 1 : 0;
  }
  template <class F>
  void for_each_owned(F&& f) const {
    for (size_t n = 0; n < num_nodes_; ++n)
      if (!distributed_ || owned_[n]) f(n);
  }
  /// The recorded forces' work of the step, phase 0: f . (v^n + v^{n+1}) / 2 dt, or f . v^{n+1}
  /// dt at a component a condition holds (there its reaction cancels the force, and both are
  /// taken at the velocity the condition imposes).
  void recorded_work(const GridUpdate& u) {
    const PhaseUpdate& ph = u.phases[0];
    const HeldComponents* held = u.held[0];
    for (size_t kind = 0; kind < applied_.size(); ++kind) {
      if (!recorded_[kind]) continue;
      const std::vector<double>& f = applied_[kind];
      double w = 0;
      for_each_owned([&](size_t n) {
        const double* s = free_.data() + n * 2 * D;
        for (int d = 0; d < D; ++d) {
          const double v = ph.velocity.at(n, d);
          const double v_mean = held && held->held(n, d) ? v : 0.5 * (v + s[D + d]);
          w += f[n * D + size_t(d)] * v_mean;
        }
      });
      node_work_[kind] += u.dt * w;
    }
  }

  size_t num_nodes_ = 0;
  std::vector<Padded> per_thread_;  // per thread, the step's drag and contact dissipation
  // Per set and particle index, the step's sums of the block that begins there: blocks begin
  // where the partition's ranges do, not on multiples of kBlock.
  std::vector<std::vector<BlockSums>> blocks_;
  std::array<std::vector<double>, 3> applied_;  // per kind, the step's recorded nodal forces
  std::array<bool, 3> recorded_{};
  std::array<double, 3> node_work_{};
  std::vector<double> before_;
  std::vector<double> free_;  // per phase and node: the velocity before the conditions, v^n
  std::vector<char> owned_;
  bool distributed_ = false;
};

}  // namespace loam
