// Circular cylinder along a coordinate axis: in 3D between `from` and `to` along it, in 2D a disk
// (axis z, the out-of-plane one). It describes its wall (surface_samples, outward normals radial
// from the axis), so a cylinder can be a borehole for cavity_pressure; its end caps carry no
// samples (a borehole's pressure acts on its wall only).
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "surface_samples.hpp"

namespace loam {

template <int D>
class Cylinder : public Generator<D> {
 public:
  static constexpr const char* name = "cylinder";
  static constexpr const char* summary =
      "circular cylinder along x, y or z (3D; a disk in 2D, axis z): boreholes, piles, tunnels";
  static Schema schema() {
    Schema s;
    s.choice("axis", {"x", "y", "z"}, "direction of the cylinder's axis (2D: z only)").def("z");
    s.vector("center", "m",
             "a point on the axis (its coordinate along the axis is not used; 2D: the disk's "
             "centre)")
        .required();
    s.real("radius", "m", "radius").required().positive();
    s.real("from", "m", "3D: where the cylinder starts along its axis (required in 3D)");
    s.real("to", "m", "3D: where it ends along its axis (> from; required in 3D)");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.has("from") && p.has("to") && p.real("to") <= p.real("from"))
        d.error(p.where("to"), p.path("to"), "'to' must be larger than 'from'");
    });
    return s;
  }
  explicit Cylinder(const Params& p)
      : axis_(p.text("axis")[0] - 'x'),
        r_(p.real("radius")),
        from_(p.has("from") ? p.real("from") : 0),
        to_(p.has("to") ? p.real("to") : 0),
        has_ends_(p.has("from") && p.has("to")) {
    for (int d = 0; d < D; ++d) c_[size_t(d)] = p.vec("center")[size_t(d)];
  }
  std::string check() const override {
    if (D == 1) return "a cylinder needs a 2D or 3D grid";
    if (D == 2 && axis_ != 2)
      return "in 2D a cylinder is a disk in the plane: its axis must be z (for a segment or "
             "strip use box)";
    if (D == 3 && !has_ends_) return "a 3D cylinder needs 'from' and 'to' along its axis";
    return "";
  }
  bool contains(const std::array<double, D>& x) const override {
    if (D == 3 && (x[size_t(axis_)] < from_ || x[size_t(axis_)] > to_)) return false;
    return distance_from_axis(x) <= r_;
  }
  std::array<double, D> lower() const override { return bound(-1); }
  std::array<double, D> upper() const override { return bound(+1); }

  /// The wall: circle_rule about the axis, times a midpoint rule along it in 3D.
  std::vector<typename Generator<D>::SurfaceSample> surface_samples(double spacing) const override {
    std::vector<typename Generator<D>::SurfaceSample> out;
    const int u = (axis_ + 1) % 3, v = (axis_ + 2) % 3;  // the plane normal to the axis (3D)
    const int along = D == 3 ? std::max(1, int(std::ceil((to_ - from_) / spacing))) : 1;
    const double length = D == 3 ? (to_ - from_) / along : 1;
    for (int j = 0; j < along; ++j)
      for (const auto& [t, arc] : circle_rule(r_, spacing)) {
        typename Generator<D>::SurfaceSample q{};
        q.normal[size_t(D == 3 ? u : 0)] = std::cos(t);
        q.normal[size_t(D == 3 ? v : 1)] = std::sin(t);
        for (int d = 0; d < D; ++d) q.x[size_t(d)] = c_[size_t(d)] + r_ * q.normal[size_t(d)];
        if (D == 3) q.x[size_t(axis_)] = from_ + (j + 0.5) * length;
        q.area = arc * length;
        out.push_back(q);
      }
    return out;
  }

 private:
  double distance_from_axis(const std::array<double, D>& x) const {
    double r2 = 0;
    for (int d = 0; d < D; ++d)
      if (d != axis_) r2 += (x[size_t(d)] - c_[size_t(d)]) * (x[size_t(d)] - c_[size_t(d)]);
    return std::sqrt(r2);
  }
  std::array<double, D> bound(int side) const {
    std::array<double, D> b{};
    for (int d = 0; d < D; ++d)
      b[size_t(d)] = d == axis_ ? (side < 0 ? from_ : to_) : c_[size_t(d)] + side * r_;
    return b;
  }
  int axis_;
  std::array<double, D> c_{};
  double r_, from_, to_;
  bool has_ends_;
};

LOAM_REGISTER(Generator, Cylinder)

}  // namespace loam
