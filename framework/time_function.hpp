#pragma once
// Time-function plugin interface: a scalar factor f(t) of the time t (s) since the start of the
// stage that set its owner (a load's time: Simulation::loads_start), e.g. a ramp, a pulse or a
// table. A load multiplies its magnitude by it (issue 16: the blast's pressure pulse).
namespace loam {

template <int D>
class TimeFunction {
 public:
  static constexpr const char* kind = "time_function";
  virtual ~TimeFunction() = default;
  virtual double value(double t) const = 0;
};

}  // namespace loam
