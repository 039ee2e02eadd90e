// A constant factor: f(t) = value.
#include "framework/registry.hpp"
#include "framework/time_function.hpp"

namespace loam {

template <int D>
class ConstantTime : public TimeFunction<D> {
 public:
  static constexpr const char* name = "constant";
  static constexpr const char* summary = "f(t) = value";
  static Schema schema() {
    Schema s;
    s.real("value", "-", "the factor").def("1");
    return s;
  }
  explicit ConstantTime(const Params& p) : value_(p.real("value")) {}
  double value(double) const override { return value_; }

 private:
  double value_;
};

LOAM_REGISTER(TimeFunction, ConstantTime)

}  // namespace loam
