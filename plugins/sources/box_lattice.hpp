#pragma once
// The lattice of a body's particles inside a box, shared by the sources: sites origin + (i + 1/2)
// s of the grid-aligned lattice with the body's particle spacing s (as a generator places
// them), and the layer of sites at one end of the box along an axis.
#include <array>
#include <cmath>
#include <vector>

#include "framework/grid.hpp"

namespace loam {

/// Sites origin + (i + 1/2) s inside [lo, hi]; `layer` gets those of the end layer along `axis`
/// (the upper one if `upper`, else the lower one). Both empty if the box holds no site.
template <int D>
void box_lattice(const Grid<D>& g, const std::array<double, D>& lo, const std::array<double, D>& hi,
                 const std::array<double, D>& s, int axis, bool upper,
                 std::vector<std::array<double, D>>& sites,
                 std::vector<std::array<double, D>>& layer) {
  std::array<long, D> i0{}, i1{};
  for (int d = 0; d < D; ++d) {
    const double o = g.origin[size_t(d)], sd = s[size_t(d)];
    i0[size_t(d)] = long(std::ceil((lo[size_t(d)] - o) / sd - 0.5 - 1e-9));
    i1[size_t(d)] = long(std::floor((hi[size_t(d)] - o) / sd - 0.5 + 1e-9));
    if (i1[size_t(d)] < i0[size_t(d)]) return;
  }
  const long end = upper ? i1[size_t(axis)] : i0[size_t(axis)];
  std::array<long, D> i = i0;
  while (true) {
    std::array<double, D> x{};
    for (int d = 0; d < D; ++d)
      x[size_t(d)] = g.origin[size_t(d)] + (double(i[size_t(d)]) + 0.5) * s[size_t(d)];
    sites.push_back(x);
    if (i[size_t(axis)] == end) layer.push_back(x);
    int d = 0;
    while (d < D && ++i[size_t(d)] > i1[size_t(d)]) i[size_t(d)] = i0[size_t(d)], ++d;
    if (d == D) break;
  }
}

}  // namespace loam
