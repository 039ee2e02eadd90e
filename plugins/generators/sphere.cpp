// Ball of particles: a segment in 1D, a disk in 2D, a sphere in 3D.
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Sphere : public Generator<D> {
 public:
  static constexpr const char* name = "sphere";
  static constexpr const char* summary = "ball of given centre and radius (a disk in 2D)";
  static Schema schema() {
    Schema s;
    s.vector("center", "m", "centre").required();
    s.real("radius", "m", "radius").required().positive();
    return s;
  }
  explicit Sphere(const Params& p) : r_(p.real("radius")) {
    for (int d = 0; d < D; ++d) c_[size_t(d)] = p.vec("center")[size_t(d)];
  }
  bool contains(const std::array<double, D>& x) const override {
    double r2 = 0;
    for (int d = 0; d < D; ++d)
      r2 += (x[size_t(d)] - c_[size_t(d)]) * (x[size_t(d)] - c_[size_t(d)]);
    return r2 <= r_ * r_;
  }
  std::array<double, D> lower() const override {
    auto b = c_;
    for (auto& v : b) v -= r_;
    return b;
  }
  std::array<double, D> upper() const override {
    auto b = c_;
    for (auto& v : b) v += r_;
    return b;
  }

 private:
  std::array<double, D> c_{};
  double r_;
};

LOAM_REGISTER(Generator, Sphere)

}  // namespace loam
