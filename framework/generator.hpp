#pragma once
// Particle-generator plugin interface: a region of space filled with particles at the centres of
// a regular sub-cell lattice (particles_per_cell per direction), aligned with the grid.
#include <array>
#include <string>

namespace loam {

class Diagnostics;
class Params;

template <int D>
class Generator {
 public:
  static constexpr const char* kind = "generator";
  virtual ~Generator() = default;
  virtual bool contains(const std::array<double, D>& x) const = 0;
  virtual std::array<double, D> lower() const = 0;  // bounding box
  virtual std::array<double, D> upper() const = 0;
  /// A problem with the parameters in this dimension (e.g. a polygon in 3D), or "".
  virtual std::string check() const { return ""; }
};

}  // namespace loam
