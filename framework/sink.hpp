#pragma once
// Sink plugin interface: removes particles while the run goes (an outlet, a constant water
// level). After the scheme's step a sink marks the particles of a set to remove; the Simulation
// removes them (every field of every plugin with them, through the one field layout) and counts
// their mass in the run's mass balance.
#include <array>
#include <cstdint>
#include <vector>

#include "params.hpp"

namespace loam {

template <int D>
class Simulation;
template <int D>
class ParticleSet;

template <int D>
class Sink {
 public:
  static constexpr const char* kind = "sink";
  virtual ~Sink() = default;
  virtual void setup(Simulation<D>&, Diagnostics&) {}
  /// Set remove[i] = 1 for each particle i of `set` to remove after this step (remove has the
  /// set's size and arrives zeroed or marked by other sinks).
  virtual void mark(const Simulation<D>&, const ParticleSet<D>& set,
                    std::vector<uint8_t>& remove) const = 0;
  /// Whether it would remove particles somewhere in the box [lower, upper] (a source's region).
  virtual bool overlaps(const std::array<double, D>& lower,
                        const std::array<double, D>& upper) const = 0;
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): it marks each particle
  /// from that particle alone (its rank's particles are all it sees).
  virtual bool runs_on_ranks() const { return false; }
};

/// A sink that acts on every set or on the one its `set` key names.
template <int D>
class SinkOnSets : public Sink<D> {
 public:
  explicit SinkOnSets(const Params& p) : params_(p) {}
  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (params_.has("set")) set_ = sim.set_param(params_, "set", diag);
  }
  /// Whether particles of `set` are removed by this sink.
  bool acts_on(const Simulation<D>& sim, const ParticleSet<D>& set) const {
    return set_ < 0 || &set == &sim.sets[size_t(set_)];
  }
  static void add_set_param(Schema& s) {
    s.text("set", "remove only particles of this set (default: every set)");
  }

 protected:
  Params params_;
  int set_ = -1;  // -1: every set
};

}  // namespace loam
