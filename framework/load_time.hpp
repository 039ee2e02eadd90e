#pragma once
// How a load's magnitude varies in time: its `time_function` (a plugin, docs/plugins.md
// time_function), or the linear ramp of the older `ramp_time` key. One definition for every load.
#include <memory>

#include "load.hpp"
#include "registry.hpp"
#include "time_function.hpp"

namespace loam {

/// The keys `ramp_time` and `time_function` of a load's schema, and the check that at most one
/// is given.
inline void add_load_time_keys(Schema& s) {
  s.real("ramp_time", "s",
         "linear ramp from 0 to full load (the same as time_function: {type: linear_ramp, "
         "duration: T})")
      .def("0")
      .min(0);
  s.plugin("time_function", "time_function",
           "factor of the load over the time since its stage began (absent: 1, or the ramp)");
  s.check([](const Params& p, Diagnostics& d) {
    if (p.present("ramp_time") && p.present("time_function"))
      d.error(p.where("ramp_time"), p.path("ramp_time"),
              "give either ramp_time or time_function (a ramp is time_function: {type: "
              "linear_ramp, duration: T})");
  });
}

/// A plugin's optional `time_function`, its clock starting at `start`: value(t) = f(t - start),
/// integral(t0, t1) = the integral of f(t - start) over [t0, t1]; without one 1 and t1 - t0
/// (loads, sources, prescribed boundary values).
template <int D>
class TimeFactor {
 public:
  explicit TimeFactor(const Params& p, double start = 0) : start_(start) {
    if (p.present("time_function"))
      f_ = Registry::instance().create<TimeFunction, D>(p.section("time_function"));
  }
  bool present() const { return f_ != nullptr; }
  double value(double t) const { return f_ ? f_->value(t - start_) : 1.0; }
  double integral(double t0, double t1) const {
    return f_ ? f_->integral(t0 - start_, t1 - start_) : t1 - t0;
  }

 private:
  double start_;
  std::unique_ptr<TimeFunction<D>> f_;
};

/// f(t) of a load: its time function, else the ramp (1 after ramp_time; 1 throughout for 0).
template <int D>
class LoadTime {
 public:
  explicit LoadTime(const Params& p) : ramp_(p.real("ramp_time")), f_(p) {}
  double operator()(double t) const { return f_.present() ? f_.value(t) : ramp_factor(t, ramp_); }

 private:
  double ramp_;
  TimeFactor<D> f_;
};

}  // namespace loam
