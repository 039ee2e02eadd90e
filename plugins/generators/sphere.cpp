// Ball of particles: a segment in 1D, a disk in 2D, a sphere in 3D. It describes its surface,
// so it can be a cavity for cavity_pressure (a spherical charge, or a hole in 2D).
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "surface_samples.hpp"

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
  std::vector<typename Generator<D>::SurfaceSample> surface_samples(double spacing) const override {
    std::vector<typename Generator<D>::SurfaceSample> out;
    auto add = [&](const std::array<double, 3>& n, double area) {
      typename Generator<D>::SurfaceSample q{};
      for (int d = 0; d < D; ++d) {
        q.normal[size_t(d)] = n[size_t(d)];
        q.x[size_t(d)] = c_[size_t(d)] + r_ * n[size_t(d)];
      }
      q.area = area;
      out.push_back(q);
    };
    if constexpr (D == 1) {
      add({-1, 0, 0}, 1);
      add({1, 0, 0}, 1);
    } else if constexpr (D == 2) {
      for (const auto& [t, arc] : circle_rule(r_, spacing)) add({std::cos(t), std::sin(t), 0}, arc);
    } else {
      for (const auto& q : sphere_rule(r_, spacing)) add(q.normal, q.area);
    }
    return out;
  }

 private:
  std::array<double, D> c_{};
  double r_;
};

LOAM_REGISTER(Generator, Sphere)

}  // namespace loam
