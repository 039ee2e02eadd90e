#pragma once
// Particle-generator plugin interface: a region of space filled with particles at the centres of
// a regular sub-cell lattice (particles_per_cell per direction), aligned with the grid.
#include <array>
#include <string>
#include <vector>

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

  /// A point of the region's surface with its outward normal and the surface area it stands
  /// for, from surface_samples.
  struct SurfaceSample {
    std::array<double, D> x, normal;
    double area;  // m^(D-1) (1D: 1; 2D: per unit thickness)
  };
  /// The region's surface as quadrature points about `spacing` apart whose areas sum to the
  /// surface's (exactly, up to round-off), for a load on the wall of a cavity (cavity_pressure).
  /// Empty for a region that does not describe its surface (default); a cylinder gives its
  /// wall, not its ends. Samples are symmetric about the coordinate planes through the region's
  /// centre, so a quarter of them covers a quarter model's wall exactly.
  virtual std::vector<SurfaceSample> surface_samples(double /*spacing*/) const { return {}; }
};

}  // namespace loam
