#pragma once
// Boundary-condition plugin interface: constrains nodal velocity (and acceleration) components.
// Schemes call constrain() on every nodal vector that must respect the constraint, and
// constrain_grid_update() once on the grid update of a step (all phases, with nodal masses).
#include <array>
#include <string>
#include <vector>

#include "grid.hpp"

namespace loam {

template <int D>
class Simulation;
class Diagnostics;
class Params;

/// One phase of a grid update: the updated nodal velocity v^{n+1}, the acceleration a with
/// v^{n+1} = v^n + dt a, and the phase's lumped nodal mass mass.at(n, 0) (kg; per unit area in
/// 1D and per unit thickness in 2D, like the particle masses). Nodes with no mass have zero
/// velocity and acceleration.
struct PhaseUpdate {
  NodalVector velocity, acceleration, mass;
};

/// The grid update of one step, after the scheme's own implicit terms (e.g. drag). phases[0] is
/// the scheme's only phase or the solid skeleton; phases[1], when count == 2, is the pore water
/// of a two-phase scheme (its velocity is the water's own, not relative to the skeleton).
struct GridUpdate {
  std::array<PhaseUpdate, 2> phases;
  int count = 1;
  double dt = 0;
};

template <int D>
class Boundary {
 public:
  static constexpr const char* kind = "boundary";
  virtual ~Boundary() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Zero the constrained components of `v` (a velocity, momentum, acceleration or force).
  virtual void constrain(const NodalVector& v) const = 0;
  /// Constrain the velocity v^{n+1} and acceleration a of a grid update together (v^{n+1} =
  /// v^n + dt a). A condition that depends on the motion (Coulomb friction, contact) overrides
  /// this and keeps a consistent with the velocity it imposes, so FLIP particles see it too.
  virtual void constrain_update(const NodalVector& v, const NodalVector& a, double /*dt*/) const {
    constrain(v);
    constrain(a);
  }
  /// The whole grid update of a step: every phase at once, with the nodal masses. A condition
  /// that applies a force integrated implicitly (a dashpot: v^{n+1} = m v* / (m + dt C) needs m)
  /// or that couples the phases overrides this. Default: constrain_update of each phase.
  virtual void constrain_grid_update(const GridUpdate& u) const {
    for (int k = 0; k < u.count; ++k)
      constrain_update(u.phases[size_t(k)].velocity, u.phases[size_t(k)].acceleration, u.dt);
  }
};

/// The nodes on one face of the grid ("x-", "x+", "y-", ...), for face-based plugins.
struct Face {
  int axis = 0;
  bool upper = false;
};
Face parse_face(const std::string& name);
template <int D>
std::vector<size_t> face_nodes(const Grid<D>& grid, const Face& face);
/// Report a face that does not exist in this dimension; returns false then.
bool check_face(const Face& f, int dim, const Params& p, const std::string& key, Diagnostics& d);
const std::vector<std::string>& face_names();

}  // namespace loam
