// Removes the particles that enter a box: an outlet, the far end of a channel.
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Region : public SinkOnSets<D> {
 public:
  using Vec = std::array<double, D>;
  static constexpr const char* name = "region";
  static constexpr const char* summary = "removes particles inside a box [min, max]";
  static Schema schema() {
    Schema s;
    s.vector("min", "m", "lower corner of the box").required();
    s.vector("max", "m", "upper corner of the box").required();
    SinkOnSets<D>::add_set_param(s);
    s.check([](const Params& p, Diagnostics& d) { check_box_corners(p, d); });
    return s;
  }
  explicit Region(const Params& p) : SinkOnSets<D>(p) {
    for (int d = 0; d < D; ++d)
      lo_[size_t(d)] = p.vec("min")[size_t(d)], hi_[size_t(d)] = p.vec("max")[size_t(d)];
  }
  bool runs_on_ranks() const override { return true; }  // per particle
  void mark(const Simulation<D>& sim, const ParticleSet<D>& set,
            std::vector<uint8_t>& remove) const override {
    if (!this->acts_on(sim, set)) return;
    const Particles<D>& P = set.particles;
    for (size_t i = 0; i < P.size(); ++i) {
      bool in = true;
      for (int d = 0; d < D; ++d) {
        const double x = P.col(P.position, d)[i];
        in = in && x >= lo_[size_t(d)] && x <= hi_[size_t(d)];
      }
      if (in) remove[i] = 1;
    }
  }
  bool overlaps(const Vec& lo, const Vec& hi) const override {
    for (int d = 0; d < D; ++d)
      if (hi[size_t(d)] < lo_[size_t(d)] || lo[size_t(d)] > hi_[size_t(d)]) return false;
    return true;
  }

 private:
  Vec lo_{}, hi_{};
};

LOAM_REGISTER(Sink, Region)

}  // namespace loam
