// Field varying linearly along one axis: value + gradient * (x_axis - origin), e.g. a geostatic
// stress sigma(z) = rho g (z - H) for an initial state in equilibrium with gravity.
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class LinearProfile : public Field<D> {
 public:
  static constexpr const char* name = "linear_profile";
  static constexpr const char* summary =
      "value + gradient * (x[axis] - origin), e.g. geostatic stress";
  static Schema schema() {
    Schema s;
    s.vector("value", "(field unit)", "value at the origin", kFieldComponents).required();
    s.vector("gradient", "(field unit)/m", "change per metre along the axis", kFieldComponents)
        .required();
    s.integer("axis", "axis index (0: x, 1: y, 2: z)").required().min(0).max(2);
    s.real("origin", "m", "coordinate along the axis where the field equals value").def("0");
    return s;
  }
  explicit LinearProfile(const Params& p)
      : v_(p.vec("value")),
        g_(p.vec("gradient")),
        axis_(int(p.integer("axis"))),
        x0_(p.real("origin")) {
    if (axis_ >= D) axis_ = D - 1;
  }
  void value(const std::array<double, D>& x, double* out) const override {
    for (size_t c = 0; c < v_.size(); ++c) out[c] = v_[c] + g_[c] * (x[size_t(axis_)] - x0_);
  }

 private:
  std::vector<double> v_, g_;
  int axis_;
  double x0_;
};

LOAM_REGISTER(Field, LinearProfile)

}  // namespace loam
