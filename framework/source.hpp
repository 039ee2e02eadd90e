#pragma once
// Source plugin interface: creates particles while the run goes (an inlet, a constant inflow).
// A source creates the particles of a named body (its material, set and particle spacing)
// through Simulation::add_particles, which initialises every field the run's plugins requested
// the same way as at t = 0 and gives them fresh ids (never reused).
#include <array>

namespace loam {

template <int D>
class Simulation;
class Diagnostics;

template <int D>
class Source {
 public:
  static constexpr const char* kind = "source";
  virtual ~Source() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// At time t (at set-up, t = 0, and after every step, before the next one's time step is
  /// chosen): create particles, prescribe velocities.
  virtual void apply(Simulation<D>&, double t) = 0;
  /// The box where it creates particles (for the check that no sink removes them there).
  virtual void region(std::array<double, D>& lower, std::array<double, D>& upper) const = 0;
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): every rank passes the
  /// same points to Simulation::add_particles (which keeps each rank's own), so what it creates
  /// may depend only on its own state, the time and reductions over the ranks.
  virtual bool runs_on_ranks() const { return false; }
  /// Checkpoints (output.checkpoint): the plugin's accumulated state as doubles, restored
  /// bit for bit on --resume. false: it has none implemented yet, and a checkpointed run with
  /// it is refused (a silently lost state would break the resumed run's results).
  virtual bool save_state(std::vector<double>&) const { return false; }
  virtual void restore_state(const std::vector<double>&) {}
};

}  // namespace loam
