#pragma once
// Boundary-condition plugin interface: constrains nodal velocity (and acceleration) components.
// Schemes call constrain() on every nodal vector that must respect the constraint.
#include <string>
#include <vector>

#include "grid.hpp"

namespace loam {

template <int D>
class Simulation;
class Diagnostics;
class Params;

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
