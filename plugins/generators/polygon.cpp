// Simple polygon (2D only): particles at lattice points inside it (even-odd rule).
#include <algorithm>
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Polygon : public Generator<D> {
 public:
  static constexpr const char* name = "polygon";
  static constexpr const char* summary = "2D polygon given by its vertices (slopes, embankments)";
  static Schema schema() {
    Schema s;
    s.vector_list("vertices", "m", "polygon vertices in order (at least 3)", 2).required();
    s.check([](const Params& p, Diagnostics& d) {
      if (p.vecs("vertices").size() < 3)
        d.error(p.where("vertices"), p.path("vertices"), "a polygon needs at least 3 vertices");
    });
    return s;
  }
  explicit Polygon(const Params& p) : v_(p.vecs("vertices")) {}
  std::string check() const override {
    return D == 2 ? ""
                  : "a polygon generator needs a 2D grid (this one is " + std::to_string(D) + "D)";
  }
  bool contains(const std::array<double, D>& x) const override {
    if constexpr (D != 2) {
      return false;
    } else {
      bool in = false;
      for (size_t i = 0, j = v_.size() - 1; i < v_.size(); j = i++) {
        const auto &a = v_[i], &b = v_[j];
        if ((a[1] > x[1]) != (b[1] > x[1]) &&
            x[0] < (b[0] - a[0]) * (x[1] - a[1]) / (b[1] - a[1]) + a[0])
          in = !in;
      }
      return in;
    }
  }
  std::array<double, D> lower() const override { return bound(false); }
  /// Each edge split into equal pieces at most `spacing` long, one sample at each piece's
  /// midpoint with the edge's outward normal (the side away from the polygon's interior, from
  /// the sign of its area, so either vertex order works) and the piece's length as its area.
  std::vector<typename Generator<D>::SurfaceSample> surface_samples(double spacing) const override {
    std::vector<typename Generator<D>::SurfaceSample> out;
    if constexpr (D == 2) {
      double twice_area = 0;
      for (size_t i = 0, j = v_.size() - 1; i < v_.size(); j = i++)
        twice_area += v_[j][0] * v_[i][1] - v_[i][0] * v_[j][1];
      const double turn = twice_area > 0 ? 1.0 : -1.0;  // counter-clockwise: normal (dy, -dx)
      for (size_t j = 0; j < v_.size(); ++j) {
        const auto &a = v_[j], &b = v_[(j + 1) % v_.size()];
        const double dx = b[0] - a[0], dy = b[1] - a[1], length = std::hypot(dx, dy);
        if (length == 0) continue;
        const int pieces = std::max(1, int(std::ceil(length / spacing)));
        for (int k = 0; k < pieces; ++k) {
          const double t = (k + 0.5) / pieces;
          out.push_back({{a[0] + t * dx, a[1] + t * dy},
                         {turn * dy / length, -turn * dx / length},
                         length / pieces});
        }
      }
    }
    return out;
  }
  std::array<double, D> upper() const override { return bound(true); }

 private:
  std::array<double, D> bound(bool up) const {
    std::array<double, D> b{};
    for (int d = 0; d < std::min(D, 2); ++d) {
      b[size_t(d)] = v_[0][size_t(d)];
      for (const auto& p : v_)
        b[size_t(d)] =
            up ? std::max(b[size_t(d)], p[size_t(d)]) : std::min(b[size_t(d)], p[size_t(d)]);
    }
    return b;
  }
  std::vector<std::vector<double>> v_;
};

LOAM_REGISTER(Generator, Polygon)

}  // namespace loam
