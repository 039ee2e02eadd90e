// Removes the particles that leave the grid through a face no mechanical condition holds (an
// outflow through the open end of a channel, a splash over the top of a tank), instead of
// stopping the run as unstable (exit 3). Held faces hold their particles anyway
// (Simulation::held_faces), so only open faces let particles out.
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class OpenFaces : public SinkOnSets<D> {
 public:
  using Vec = std::array<double, D>;
  static constexpr const char* name = "open_faces";
  static constexpr const char* summary =
      "removes particles that leave the grid through a face no mechanical condition holds";
  static Schema schema() {
    Schema s;
    SinkOnSets<D>::add_set_param(s);
    return s;
  }
  explicit OpenFaces(const Params& p) : SinkOnSets<D>(p) {}

  bool runs_on_ranks() const override { return true; }  // per particle
  void mark(const Simulation<D>& sim, const ParticleSet<D>& set,
            std::vector<uint8_t>& remove) const override {
    if (!this->acts_on(sim, set)) return;
    const Particles<D>& P = set.particles;
    for (size_t i = 0; i < P.size(); ++i)
      for (int d = 0; d < D; ++d) {
        const double x = P.col(P.position, d)[i];
        if (x < sim.grid.origin[size_t(d)] || x > sim.grid.upper(d)) remove[i] = 1;
      }
  }
  /// A source region lies inside the grid, where this sink removes nothing.
  bool overlaps(const Vec&, const Vec&) const override { return false; }
};

LOAM_REGISTER(Sink, OpenFaces)

}  // namespace loam
