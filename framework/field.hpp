#pragma once
// Spatial-field plugin interface, for initial conditions (velocity, stress): a value with a
// fixed number of components at every point. A bare list in YAML means `type: constant`.
#include <array>

namespace loam {

template <int D>
class Field {
 public:
  static constexpr const char* kind = "field";
  virtual ~Field() = default;
  virtual void value(const std::array<double, D>& x, double* out) const = 0;
};

}  // namespace loam
