#pragma once
// Load plugin interface. A load adds to the particles' external force before the scatter, or to
// nodal forces after it, at time t.
#include "grid.hpp"

namespace loam {

template <int D>
class Simulation;
class Diagnostics;

template <int D>
class Load {
 public:
  static constexpr const char* kind = "load";
  virtual ~Load() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Add to the `external_force` particle field (zeroed by the framework every step).
  virtual void apply_to_particles(Simulation<D>&, double /*t*/) {}
  /// Add to nodal forces after the scatter.
  virtual void apply_to_grid(Simulation<D>&, const NodalVector& /*force*/, double /*t*/) {}
  /// Whether this load writes particle external forces (the field is allocated only then).
  virtual bool uses_particle_forces() const { return false; }
  /// Whether apply_to_grid adds nodal forces: their work then goes to the energy balance
  /// (framework/energy_ledger.hpp), which records the nodal forces around the call.
  virtual bool uses_grid_forces() const { return false; }
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): it reads and writes only
  /// the particles of this rank and the stored box of nodes, each node as the whole grid's
  /// value. Default false: a run under mpirun refuses it with a located error.
  virtual bool runs_on_ranks() const { return false; }
};

/// Linear ramp from 0 at t=0 to 1 at t=ramp_time (1 throughout if ramp_time is 0).
inline double ramp_factor(double t, double ramp_time) {
  return ramp_time > 0 && t < ramp_time ? t / ramp_time : 1.0;
}

}  // namespace loam
