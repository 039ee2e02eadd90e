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

template <int D>
class Damping {
 public:
  static constexpr const char* kind = "damping";
  virtual ~Damping() = default;
  virtual void apply(Simulation<D>&, const NodeForces&) = 0;
};

}  // namespace loam
