#pragma once
// Work partition of the particles for threaded kernels.
//
// Particles are counting-sorted by (material, cell) every few steps: each material's particles
// are one contiguous range (so a material update is a batch call), and inside it they are in
// cell order (locality: neighbouring particles hit the same nodes). The cell order (the slowest
// grid axis varies slowest) is cut into slabs of equal particle count; a slab is one index range
// per material. Slabs are coloured alternately: two slabs of one colour are separated by more
// rows than the stencil reaches, so they never write the same node, and a
// particle-to-grid scatter runs race-free without atomics or locks: all colour-0 slabs in
// parallel, then all colour-1 slabs (docs/architecture.md "Threads without locks";
// measured 1.7-1.8x on 2 threads). A node is written by at most two neighbouring slabs, the
// colour-0 one first, each in its particle order, whichever thread runs them; the slabs are
// cut without regard to the thread count, and one thread runs them in the same colour order,
// so a node's sums, and the whole run, have the same bits on any number of threads.
//
// Between sorts particles drift; verify() measures each slab's actual row extent every step and
// reports when the colouring is no longer safe, so the caller re-sorts.
#include <omp.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"
#include "shape_function.hpp"

namespace loam {

struct IndexRange {
  size_t begin = 0, end = 0;
};

template <int D>
class Partition {
 public:
  struct Slab {
    std::vector<IndexRange> ranges;  // one per material with particles in the slab
    int row_min = 0, row_max = -1;   // actual rows spanned now
  };

  /// The most slabs a sort cuts (fewer where they would get too thin for the stencil).
  static constexpr int kMaxSlabs = 64;

  std::vector<Slab> slabs;
  std::vector<IndexRange> material_ranges;
  int threads = 1;

  /// Sort particles by (material, cell) and rebuild slabs. `reach` = rows_below + rows_above
  /// of the shape function.
  void sort(Particles<D>& p, const Grid<D>& g, int num_materials, int reach, int num_threads);

  /// Measure each slab's row extent. Returns false if same-colour slabs could now write the
  /// same node rows (then sort again).
  bool verify(const Particles<D>& p, const Grid<D>& g, int rows_below, int rows_above);

  /// Blocks for a scatter (particle-to-grid): race-free by slab colouring.
  /// f(begin, count, thread) with count <= kBlock; never spans two materials.
  template <class F>
  void scatter_blocks(F&& f) const {
    const int n = int(slabs.size());
    for (int colour = 0; colour < 2; ++colour) {
      if (threads <= 1 || n < 3) {
        for (int s = colour; s < n; s += 2) run_slab(slabs[size_t(s)], f, 0);
        continue;
      }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
      for (int s = colour; s < n; s += 2) run_slab(slabs[size_t(s)], f, omp_get_thread_num());
    }
  }

  /// Blocks for a gather (grid-to-particle, material update): any order, all threads.
  template <class F>
  void gather_blocks(F&& f) const {
    const int n = int(slabs.size());
    if (threads <= 1) {
      for (const auto& s : slabs) run_slab(s, f, 0);
      return;
    }
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
    for (int s = 0; s < n; ++s) run_slab(slabs[size_t(s)], f, omp_get_thread_num());
  }

 private:
  /// Measure slab row extents; true if same-colour slabs are more than reach + margin rows apart.
  bool separated(const Particles<D>& p, const Grid<D>& g, int reach, int margin);
  template <class F>
  static void run_slab(const Slab& s, F& f, int thread) {
    for (const auto& r : s.ranges)
      for (size_t b = r.begin; b < r.end; b += kBlock)
        f(b, int(std::min<size_t>(kBlock, r.end - b)), thread);
  }
  std::vector<uint32_t> counts_, order_;
  std::vector<uint32_t> keys_;
};

}  // namespace loam
