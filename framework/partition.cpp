#include "partition.hpp"

#include <cmath>

namespace loam {

template <int D>
void Partition<D>::sort(Particles<D>& p, const Grid<D>& g, int num_materials, int reach,
                        int num_threads) {
  threads = num_threads;
  const size_t n = p.size();
  const size_t ncells = g.num_cells;
  const size_t nkeys = size_t(num_materials) * ncells;
  keys_.resize(n);
  std::array<const double*, D> x{};
  for (int d = 0; d < D; ++d) x[size_t(d)] = p.col(p.position, d);
#pragma omp parallel for schedule(static) num_threads(threads)
  for (size_t i = 0; i < n; ++i) {
    size_t c = 0;
    for (int d = 0; d < D; ++d)
      c += size_t(g.cell_of(x[size_t(d)][i], d)) * size_t(g.cell_stride[d]);
    keys_[i] = uint32_t(size_t(p.material[i]) * ncells + c);
  }
  // Stable counting sort; counts_[k] becomes the first index of key k.
  counts_.assign(nkeys + 1, 0);
  for (size_t i = 0; i < n; ++i) ++counts_[keys_[i] + 1];
  for (size_t k = 0; k < nkeys; ++k) counts_[k + 1] += counts_[k];
  order_.resize(n);
  {
    std::vector<uint32_t> next(counts_.begin(), counts_.end() - 1);
    for (size_t i = 0; i < n; ++i) order_[next[keys_[i]]++] = uint32_t(i);
  }
  p.permute(order_, threads);

  material_ranges.assign(size_t(num_materials), {});
  for (int m = 0; m < num_materials; ++m)
    material_ranges[size_t(m)] = {counts_[size_t(m) * ncells], counts_[size_t(m + 1) * ncells]};

  // Cut the cell order into slabs of equal particle count (cuts may fall inside a row), as many
  // as keep same-colour slabs apart, up to kMaxSlabs. Balanced slabs matter: a colour phase
  // lasts as long as its busiest thread. The slabs do not depend on the thread count, so neither
  // does the order in which a node's sums are added (header): a run gives the same bits on
  // any number of threads.
  std::vector<size_t> before(ncells + 1, 0);  // particles in cells < c, over all materials
  for (size_t c = 0; c <= ncells; ++c)
    for (int m = 0; m < num_materials; ++m)
      before[c] += counts_[size_t(m) * ncells + c] - counts_[size_t(m) * ncells];
  auto build = [&](int num_slabs) {
    slabs.clear();
    size_t c0 = 0;
    for (int k = 1; k <= num_slabs; ++k) {
      size_t target = n * size_t(k) / size_t(num_slabs);
      size_t c1 = k == num_slabs
                      ? ncells
                      : size_t(std::lower_bound(before.begin() + long(c0), before.end(), target) -
                               before.begin());
      c1 = std::min(c1, ncells);
      Slab slab;
      for (int m = 0; m < num_materials; ++m) {
        IndexRange r{counts_[size_t(m) * ncells + c0], counts_[size_t(m) * ncells + c1]};
        if (r.end > r.begin) slab.ranges.push_back(r);
      }
      slabs.push_back(std::move(slab));
      c0 = c1;
    }
  };
  // One spare row between same-colour slabs, so particles may drift before a re-sort is due.
  constexpr int kMargin = 1;
  for (int num_slabs = kMaxSlabs; num_slabs >= 3; num_slabs -= 2) {
    build(num_slabs);
    if (separated(p, g, reach, kMargin)) return;
  }
  build(1);
}

template <int D>
bool Partition<D>::separated(const Particles<D>& p, const Grid<D>& g, int reach, int margin) {
  // Measure each slab's row extent from its particles.
  const double* z = p.col(p.position, D - 1);
  const int n = int(slabs.size());
#pragma omp parallel for schedule(dynamic, 1) num_threads(threads)
  for (int s = 0; s < n; ++s) {
    Slab& slab = slabs[size_t(s)];
    int lo = 1 << 30, hi = -1;
    for (const auto& r : slab.ranges)
      for (size_t i = r.begin; i < r.end; ++i) {
        int row = g.cell_of(z[i], D - 1);
        lo = std::min(lo, row);
        hi = std::max(hi, row);
      }
    slab.row_min = lo;
    slab.row_max = hi;
  }
  if (slabs.size() < 3) return true;
  // Same-colour slabs must be further apart than the stencil reach (plus the margin).
  for (int colour = 0; colour < 2; ++colour) {
    int last_max = -(1 << 29);
    for (int s = colour; s < n; s += 2) {
      const Slab& slab = slabs[size_t(s)];
      if (slab.row_max < 0) continue;  // empty
      if (slab.row_min - last_max <= reach + margin) return false;
      last_max = std::max(last_max, slab.row_max);
    }
  }
  return true;
}

template <int D>
bool Partition<D>::verify(const Particles<D>& p, const Grid<D>& g, int rows_below, int rows_above) {
  return separated(p, g, rows_below + rows_above, 0);
}

template class Partition<1>;
template class Partition<2>;
template class Partition<3>;

}  // namespace loam
