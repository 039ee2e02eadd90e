#pragma once
// Damping plugin interface: modifies nodal forces before the grid integration.
#include "grid.hpp"

namespace loam {

template <int D>
class Simulation;

struct NodeForces {
  const double* mass;  // mass[n*stride]
  NodalVector momentum;
  NodalVector force;
  size_t num_nodes;
  int stride;
};

/// The momentum balances a two-phase scheme hands to a damping: the skeleton's (or the
/// mixture's) only, or the liquid's as well.
enum class DampedPhases { solid, solid_and_liquid };

/// The momentum balance a damping acts on, in the grid update's phase order: the only phase, the
/// skeleton or the mixture; a two-phase scheme's liquid.
enum class MomentumBalance { kSolid = 0, kLiquid = 1 };

template <int D>
class Damping {
 public:
  static constexpr const char* kind = "damping";
  virtual ~Damping() = default;
  virtual void apply(Simulation<D>&, const NodeForces&) = 0;
  /// Default: the solid only. Damping the liquid too brings water to rest (a settle stage), but
  /// it would slow steady seepage, where the water's force balances the drag.
  virtual DampedPhases phases() const { return DampedPhases::solid; }
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): it reads and writes only
  /// the particles of this rank and the stored box of nodes, each node as the whole grid's
  /// value. Default false: a run under mpirun refuses it with a located error.
  virtual bool runs_on_ranks() const { return false; }
};

}  // namespace loam
