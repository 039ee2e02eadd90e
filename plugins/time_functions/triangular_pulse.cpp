// A triangular pulse: 0 until `start`, linearly up to `peak` at `peak_time`, linearly down to 0
// at `end_time`, 0 after (the blast of "The Material Point Method: A promising computational
// tool in Geotechnics", seed 002: 2.5 GPa at 0.017 s, ending at 0.034 s).
#include "framework/registry.hpp"
#include "framework/time_function.hpp"

namespace loam {

template <int D>
class TriangularPulse : public TimeFunction<D> {
 public:
  static constexpr const char* name = "triangular_pulse";
  static constexpr const char* summary =
      "0 until start, linearly to `peak` at peak_time, linearly back to 0 at end_time";
  static Schema schema() {
    Schema s;
    s.real("start", "s", "when the pulse begins").def("0").min(0);
    s.real("peak_time", "s", "when it peaks").required().positive();
    s.real("end_time", "s", "when it has ended").required().positive();
    s.real("peak", "-", "the factor at the peak").def("1");
    s.check([](const Params& p, Diagnostics& d) {
      if (!(p.real("start") < p.real("peak_time")))
        d.error(p.where("peak_time"), p.path("peak_time"), "peak_time must be after start");
      if (!(p.real("peak_time") < p.real("end_time")))
        d.error(p.where("end_time"), p.path("end_time"), "end_time must be after peak_time");
    });
    return s;
  }
  explicit TriangularPulse(const Params& p)
      : start_(p.real("start")),
        peak_time_(p.real("peak_time")),
        end_(p.real("end_time")),
        peak_(p.real("peak")) {}
  double value(double t) const override {
    if (t <= start_ || t >= end_) return 0.0;
    return peak_ * (t <= peak_time_ ? (t - start_) / (peak_time_ - start_)
                                    : (end_ - t) / (end_ - peak_time_));
  }
  void kinks(double t0, double t1, std::vector<double>& out) const override {
    for (double k : {start_, peak_time_, end_})
      if (k > t0 && k < t1) out.push_back(k);
  }

 private:
  double start_, peak_time_, end_, peak_;
};

LOAM_REGISTER(TimeFunction, TriangularPulse)

}  // namespace loam
