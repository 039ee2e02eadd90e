// Removes the particles that cross a plane: a constant water level (remove what rises above
// it), an outflow section.
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Plane : public SinkOnSets<D> {
 public:
  using Vec = std::array<double, D>;
  static constexpr const char* name = "plane";
  static constexpr const char* summary =
      "removes particles beyond a plane: (x - point) . normal > 0";
  static Schema schema() {
    Schema s;
    s.vector("point", "m", "a point of the plane").required();
    s.vector("normal", "-", "normal pointing to the side whose particles are removed").required();
    SinkOnSets<D>::add_set_param(s);
    s.check([](const Params& p, Diagnostics& d) {
      double n2 = 0;
      for (double n : p.vec("normal")) n2 += n * n;
      if (!(n2 > 0)) d.error(p.where("normal"), p.path("normal"), "the normal must not be zero");
    });
    return s;
  }
  explicit Plane(const Params& p) : SinkOnSets<D>(p) {
    double n2 = 0;
    for (int d = 0; d < D; ++d) {
      x0_[size_t(d)] = p.vec("point")[size_t(d)];
      n_[size_t(d)] = p.vec("normal")[size_t(d)];
      n2 += n_[size_t(d)] * n_[size_t(d)];
    }
    for (auto& n : n_) n /= std::sqrt(n2);
  }
  bool runs_on_ranks() const override { return true; }  // per particle
  void mark(const Simulation<D>& sim, const ParticleSet<D>& set,
            std::vector<uint8_t>& remove) const override {
    if (!this->acts_on(sim, set)) return;
    const Particles<D>& P = set.particles;
    for (size_t i = 0; i < P.size(); ++i)
      if (side(P, i) > 0) remove[i] = 1;
  }
  /// The box reaches beyond the plane if its corner furthest along the normal does.
  bool overlaps(const Vec& lo, const Vec& hi) const override {
    double s = 0;
    for (int d = 0; d < D; ++d)
      s += ((n_[size_t(d)] > 0 ? hi[size_t(d)] : lo[size_t(d)]) - x0_[size_t(d)]) * n_[size_t(d)];
    return s > 0;
  }

 private:
  Vec x0_{}, n_{};
  double side(const Particles<D>& P, size_t i) const {
    double s = 0;
    for (int d = 0; d < D; ++d) s += (P.col(P.position, d)[i] - x0_[size_t(d)]) * n_[size_t(d)];
    return s;
  }
};

LOAM_REGISTER(Sink, Plane)

}  // namespace loam
