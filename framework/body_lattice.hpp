#pragma once
// The particles a body's generator makes on this rank (framework/simulation_build.cpp): the
// centres of a regular sub-cell lattice aligned with the grid, particles_per_cell per direction
// and cell, inside the generator's region. Under mpirun each rank tests only the lattice points
// of its own block of cells (docs/parallel.md), yet numbers them as the serial run does.
#include <algorithm>
#include <array>
#include <vector>

#include "generator.hpp"
#include "grid.hpp"
#include "ranks.hpp"

namespace loam {

/// A body's lattice points origin + (i + 1/2) s, i in [i0, i1] per axis, that lie in this rank's
/// block of cells and in the generator's region, in lattice order (x fastest).
template <int D>
struct BodyLattice {
  std::vector<std::array<double, D>> x;
  std::vector<size_t> number;  // each point's serial number in the body: the body's points
                               // before it in lattice order, over the whole grid
  size_t count = 0;            // the body's points over all ranks
  std::array<double, D> lower{}, upper{};  // their bounding box, half a spacing around them
};

/// Each rank tests only the lattice points of its own cells (point i lies in cell i / ppc). To
/// number them as the serial run does, the points per lattice row (a line along x) and block
/// along x are counted on every rank, summed over the ranks, and turned into offsets in lattice
/// order: row by row, the blocks along x in order within a row.
template <int D>
BodyLattice<D> walk_body_lattice(const Grid<D>& grid, const Ranks<D>& ranks,
                                 const Generator<D>& gen, long ppc, const std::array<double, D>& s,
                                 const std::array<long, D>& i0, const std::array<long, D>& i1) {
  const auto block = ranks.cell_block(grid);
  std::array<long, D> a{}, b{};
  bool empty = false;
  long rows = 1;
  std::array<long, D> row_stride{};  // row index = sum over d >= 1 of (i - i0) row_stride
  for (size_t d = 0; d < size_t(D); ++d) {
    a[d] = std::max(i0[d], long(block.lo[d]) * ppc);
    b[d] = std::min(i1[d], long(block.hi[d]) * ppc - 1);
    empty = empty || b[d] < a[d];
    if (d > 0) row_stride[d] = rows, rows *= std::max(0L, i1[d] - i0[d] + 1);
  }
  const long segments = block.dims[0], segment = block.coord[0];
  std::vector<double> counts(size_t(rows * segments), 0.0);
  std::vector<long> row_of;
  BodyLattice<D> L;
  L.lower.fill(1e300);
  L.upper.fill(-1e300);
  std::array<long, D> i = a;
  while (!empty) {
    std::array<double, D> x{};
    for (size_t d = 0; d < size_t(D); ++d) x[d] = grid.origin[d] + (double(i[d]) + 0.5) * s[d];
    if (gen.contains(x)) {
      long row = 0;
      for (size_t d = 1; d < size_t(D); ++d) row += (i[d] - i0[d]) * row_stride[d];
      L.x.push_back(x);
      row_of.push_back(row);
      counts[size_t(row * segments + segment)] += 1;
      for (size_t d = 0; d < size_t(D); ++d) {
        L.lower[d] = std::min(L.lower[d], x[d] - 0.5 * s[d]);
        L.upper[d] = std::max(L.upper[d], x[d] + 0.5 * s[d]);
      }
    }
    size_t d = 0;
    while (d < size_t(D) && ++i[d] > b[d]) i[d] = a[d], ++d;
    if (d == size_t(D)) break;
  }
  ranks.sum(counts.data(), int(counts.size()));
  for (size_t d = 0; d < size_t(D); ++d) {
    L.lower[d] = ranks.min(L.lower[d]);
    L.upper[d] = ranks.max(L.upper[d]);
  }
  double before = 0;  // exclusive prefix sum: counts[k] becomes the points before entry k
  for (double& c : counts) {
    const double here = c;
    c = before;
    before += here;
  }
  L.count = size_t(before);
  // A rank's points of one row are consecutive along x in lattice order.
  L.number.resize(L.x.size());
  for (size_t p = 0, next = 0; p < L.x.size(); ++p) {
    if (p == 0 || row_of[p] != row_of[p - 1])
      next = size_t(counts[size_t(row_of[p] * segments + segment)]);
    L.number[p] = next++;
  }
  return L;
}

}  // namespace loam
