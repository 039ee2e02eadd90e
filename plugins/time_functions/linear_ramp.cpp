// A linear ramp: f = from until `start`, then linearly to `to` over `duration`, then `to`.
#include <algorithm>

#include "framework/registry.hpp"
#include "framework/time_function.hpp"

namespace loam {

template <int D>
class LinearRamp : public TimeFunction<D> {
 public:
  static constexpr const char* name = "linear_ramp";
  static constexpr const char* summary =
      "from `from` to `to` linearly over [start, start + duration], constant outside";
  static Schema schema() {
    Schema s;
    s.real("duration", "s", "length of the ramp").required().positive();
    s.real("start", "s", "when the ramp begins").def("0").min(0);
    s.real("from", "-", "the factor before the ramp").def("0");
    s.real("to", "-", "the factor after the ramp").def("1");
    return s;
  }
  explicit LinearRamp(const Params& p)
      : duration_(p.real("duration")),
        start_(p.real("start")),
        from_(p.real("from")),
        to_(p.real("to")) {}
  double value(double t) const override {
    const double s = std::clamp((t - start_) / duration_, 0.0, 1.0);
    return from_ + (to_ - from_) * s;
  }
  void kinks(double t0, double t1, std::vector<double>& out) const override {
    for (double k : {start_, start_ + duration_})
      if (k > t0 && k < t1) out.push_back(k);
  }

 private:
  double duration_, start_, from_, to_;
};

LOAM_REGISTER(TimeFunction, LinearRamp)

}  // namespace loam
