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
  p.permute(order_);

  material_ranges.assign(size_t(num_materials), {});
  for (int m = 0; m < num_materials; ++m)
    material_ranges[size_t(m)] = {counts_[size_t(m) * ncells], counts_[size_t(m + 1) * ncells]};

  // Cut rows of the slowest axis into slabs of about equal particle count.
  const int rows = g.cells[D - 1];
  const size_t row_cells = ncells / size_t(rows);
  auto row_start = [&](int m, int row) {
    return size_t(counts_[size_t(m) * ncells + size_t(row) * row_cells]);
  };
  std::vector<size_t> row_count(size_t(rows), 0);
  for (int m = 0; m < num_materials; ++m)
    for (int r = 0; r < rows; ++r) row_count[size_t(r)] += row_start(m, r + 1) - row_start(m, r);

  // Minimum slab width: the separating slab must cover the stencil reach, plus one row each
  // side so that particles may drift a cell before the colouring needs a re-sort.
  const int min_width = std::max(1, reach) + 2;
  const int target_slabs = threads > 1 ? 8 * threads : 1;
  const size_t target = std::max<size_t>(1, n / size_t(target_slabs));
  std::vector<std::pair<int, int>> cuts;
  int start = 0;
  size_t count = 0;
  for (int r = 0; r < rows; ++r) {
    count += row_count[size_t(r)];
    if (threads > 1 && count >= target && r + 1 - start >= min_width) {
      cuts.push_back({start, r + 1});
      start = r + 1;
      count = 0;
    }
  }
  if (start < rows) {
    if (!cuts.empty() && rows - start < min_width) cuts.back().second = rows;
    else cuts.push_back({start, rows});
  }
  slabs.clear();
  for (auto [a, b] : cuts) {
    Slab s;
    s.row_begin = a;
    s.row_end = b;
    s.row_min = a;
    s.row_max = b - 1;
    for (int m = 0; m < num_materials; ++m) {
      IndexRange r{row_start(m, a), row_start(m, b)};
      if (r.end > r.begin) s.ranges.push_back(r);
    }
    slabs.push_back(std::move(s));
  }
}

template <int D>
bool Partition<D>::verify(const Particles<D>& p, const Grid<D>& g, int rows_below,
                          int rows_above) {
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
  if (threads <= 1 || slabs.size() < 3) return true;
  // Same-colour slabs must stay apart by more than the stencil reach.
  for (int colour = 0; colour < 2; ++colour) {
    int last_max = -(1 << 29);
    for (int s = colour; s < n; s += 2) {
      const Slab& slab = slabs[size_t(s)];
      if (slab.row_max < 0) continue;  // empty
      if (slab.row_min - rows_below <= last_max + rows_above) return false;
      last_max = std::max(last_max, slab.row_max);
    }
  }
  return true;
}

template class Partition<1>;
template class Partition<2>;
template class Partition<3>;

}  // namespace loam
