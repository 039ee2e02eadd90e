// Simple polygon (2D only): particles at lattice points inside it (even-odd rule).
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
