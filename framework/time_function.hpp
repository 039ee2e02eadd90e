#pragma once
// Time-function plugin interface: a scalar factor f(t) of the time t (s) since the start of the
// stage that set its owner (a load's time: Simulation::loads_start), e.g. a ramp, a pulse or a
// table. A load multiplies its magnitude by it (the blast's pressure pulse), a
// prescribed pore pressure its value, an inflow its velocity (and the distance its particles
// travel, the integral).
#include <algorithm>
#include <vector>

namespace loam {

template <int D>
class TimeFunction {
 public:
  static constexpr const char* kind = "time_function";
  virtual ~TimeFunction() = default;
  virtual double value(double t) const = 0;
  /// The times strictly inside (t0, t1) where f has a kink (a piecewise-linear function's
  /// breakpoints), appended to `out`.
  virtual void kinks(double /*t0*/, double /*t1*/, std::vector<double>& /*out*/) const {}
  /// The integral of f over [t0, t1]: trapezoids between the kinks, exact for a piecewise-
  /// linear f (constant, ramps, pulses, tables); a smooth function overrides it (sine).
  virtual double integral(double t0, double t1) const {
    std::vector<double> t{t0};
    kinks(t0, t1, t);
    t.push_back(t1);
    double sum = 0;
    for (size_t k = 1; k < t.size(); ++k)
      sum += 0.5 * (value(t[k - 1]) + value(t[k])) * (t[k] - t[k - 1]);
    return sum;
  }
};

}  // namespace loam
