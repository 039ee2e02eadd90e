#pragma once
// One set of material points: its struct-of-arrays particles, its own partition and periodic
// sort, and the bodies it holds. A run has one or more sets on one grid; the scheme declares the
// sets it works with and what each means (Scheme::particle_sets: single_phase sums any number of
// sets onto one velocity field, a double-point scheme has `solid` and `liquid` points that move
// separately and may occupy the same place). A body picks its set with `set:`.
//
// Particle ids are unique over the whole run (bodies are numbered in config order, whatever
// their set), so an id names one particle of one set.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "particles.hpp"
#include "partition.hpp"

namespace loam {

/// A set a scheme works with, and what its particles mean (for `loam plugins` and errors).
struct SetDeclaration {
  std::string name, meaning;
};

template <int D>
class ParticleSet {
 public:
  std::string name;
  Particles<D> particles;
  Partition<D> partition;
  std::vector<int> bodies;  // indices into Simulation::bodies
  long last_sort = 0;       // step of the last sort
  bool resized = false;     // particles were added or removed since the last sort

  size_t size() const { return particles.size(); }
  /// Sum of the `mass` field (the whole mass in one-phase schemes, the solid's in two-phase).
  double mass() const {
    const double* m = particles.col(particles.mass);
    double total = 0;
    for (size_t i = 0; i < size(); ++i) total += m[i];
    return total;
  }

  /// Particle index of an id of this set (valid until the next sort); npos if not in the set.
  static constexpr size_t npos = std::numeric_limits<size_t>::max();
  size_t index_of(uint32_t id) const {
    if (!index_valid_) {
      uint32_t top = 0;
      for (uint32_t i : particles.id) top = std::max(top, i + 1);
      index_of_id_.assign(top, kNone);
      for (size_t i = 0; i < particles.size(); ++i) index_of_id_[particles.id[i]] = uint32_t(i);
      index_valid_ = true;
    }
    return id < index_of_id_.size() && index_of_id_[id] != kNone ? index_of_id_[id] : npos;
  }
  /// Call after reordering or resizing the particles.
  void invalidate_index() { index_valid_ = false; }

  /// Blocks for a scatter (race-free by slab colouring) and for a gather; see Partition.
  template <class F>
  void scatter_blocks(F&& f) const {
    partition.scatter_blocks(std::forward<F>(f));
  }
  template <class F>
  void gather_blocks(F&& f) const {
    partition.gather_blocks(std::forward<F>(f));
  }

 private:
  static constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  mutable std::vector<uint32_t> index_of_id_;
  mutable bool index_valid_ = false;
};

}  // namespace loam
