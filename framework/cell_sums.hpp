#pragma once
// Per-cell sums of particle values after the particles moved (the cell pressure of the
// two-phase schemes, the liquid points' volume and mass per cell of the double-point scheme).
//
// The colour-parallel scatter is race-free only for the positions it was coloured for; once
// the particles have moved in G2P, two points of same-coloured slabs may share a cell. Atomic
// adds from the blocks were race-free but their order followed the thread schedule, so a
// 2-thread run was not bitwise reproducible (and a resumed run not bitwise the uninterrupted
// one). Here each point's cell is found in parallel and the sums run in point order: the same
// bits at any thread count, for one add per point and value.
#include <omp.h>

#include <algorithm>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"

namespace loam {

/// The grid cell holding particle i (clamped into the grid).
template <int D>
size_t particle_cell(const Grid<D>& g, const Particles<D>& P, size_t i) {
  size_t c = 0;
  for (int d = 0; d < D; ++d)
    c += size_t(g.cell_of(P.col(P.position, d)[i], d)) * size_t(g.cell_stride[d]);
  return c;
}

/// sums[K c + k] = sum over the particles i in cell c of values(i)[k], in particle order;
/// cell[i] = the cell of particle i. `values(i, out)` writes the K values of particle i.
template <int K, int D, class Values>
void sum_per_cell(const Grid<D>& g, const Particles<D>& P, int threads, std::vector<size_t>& cell,
                  std::vector<double>& sums, Values&& values) {
  const long np = long(P.size());
  cell.resize(P.size());
#pragma omp parallel for schedule(static) num_threads(threads)
  for (long i = 0; i < np; ++i) cell[size_t(i)] = particle_cell(g, P, size_t(i));
  sums.assign(g.num_cells * K, 0.0);
  for (size_t i = 0; i < P.size(); ++i) {
    double v[K];
    values(i, v);
    double* s = sums.data() + K * cell[i];
    for (int k = 0; k < K; ++k) s[k] += v[k];
  }
}

}  // namespace loam
