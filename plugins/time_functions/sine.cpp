// A sine: f(t) = offset + amplitude sin(2 pi frequency t + phase).
#include <cmath>

#include "framework/registry.hpp"
#include "framework/time_function.hpp"

namespace loam {

template <int D>
class SineTime : public TimeFunction<D> {
 public:
  static constexpr const char* name = "sine";
  static constexpr const char* summary = "offset + amplitude sin(2 pi frequency t + phase)";
  static Schema schema() {
    Schema s;
    s.real("amplitude", "-", "amplitude of the factor").required();
    s.real("frequency", "Hz", "frequency").required().positive();
    s.real("phase", "deg", "phase at t = 0").def("0");
    s.real("offset", "-", "mean value").def("0");
    return s;
  }
  explicit SineTime(const Params& p)
      : amplitude_(p.real("amplitude")),
        omega_(2 * M_PI * p.real("frequency")),
        phase_(p.real("phase") * M_PI / 180),
        offset_(p.real("offset")) {}
  double value(double t) const override {
    return offset_ + amplitude_ * std::sin(omega_ * t + phase_);
  }
  double integral(double t0, double t1) const override {
    return offset_ * (t1 - t0) -
           amplitude_ / omega_ * (std::cos(omega_ * t1 + phase_) - std::cos(omega_ * t0 + phase_));
  }

 private:
  double amplitude_, omega_, phase_, offset_;
};

LOAM_REGISTER(TimeFunction, SineTime)

}  // namespace loam
