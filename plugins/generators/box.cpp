// Axis-aligned box of particles (1D segment, 2D rectangle, 3D brick).
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Box : public Generator<D> {
 public:
  static constexpr const char* name = "box";
  static constexpr const char* summary = "axis-aligned box [min, max]";
  static Schema schema() {
    Schema s;
    s.vector("min", "m", "lower corner").required();
    s.vector("max", "m", "upper corner").required();
    s.check([](const Params& p, Diagnostics& d) { check_box_corners(p, d); });
    return s;
  }
  explicit Box(const Params& p) {
    for (int d = 0; d < D; ++d)
      lo_[size_t(d)] = p.vec("min")[size_t(d)], hi_[size_t(d)] = p.vec("max")[size_t(d)];
  }
  bool contains(const std::array<double, D>& x) const override {
    for (int d = 0; d < D; ++d)
      if (x[size_t(d)] < lo_[size_t(d)] || x[size_t(d)] > hi_[size_t(d)]) return false;
    return true;
  }
  std::array<double, D> lower() const override { return lo_; }
  std::array<double, D> upper() const override { return hi_; }

 private:
  std::array<double, D> lo_{}, hi_{};
};

LOAM_REGISTER(Generator, Box)

}  // namespace loam
