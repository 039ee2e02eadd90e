#pragma once
// Uniform Cartesian background grid, templated on dimension. Node (i, j, k) has linear index
// i + nx*(j + ny*k); the last axis varies slowest, so slabs of cell rows along it are contiguous
// in memory and in the cell-sorted particle order.
//
// The nodes a process stores are a box of the grid, [node_lo, node_lo + box_nodes) per axis:
// the whole grid serially, a rank's owned nodes and ghost layer under MPI (docs/parallel.md,
// framework/decomposition.hpp). num_nodes, node_stride and the node index n count the box;
// node_ijk(n) and node_coord are global; nodes and cells are the whole grid's, so a face of the
// grid is where node_ijk reaches 0 or nodes - 1.
#include <array>
#include <cmath>
#include <cstddef>

namespace loam {

template <int D>
struct Grid {
  std::array<double, D> origin{}, cell{}, inv_cell{};
  std::array<int, D> cells{}, nodes{};
  std::array<int, D> node_lo{}, box_nodes{};  // the stored box of nodes (the header)
  std::array<long, D> node_stride{}, cell_stride{};
  size_t num_nodes = 0, num_cells = 0;

  void init(const std::array<double, D>& o, const std::array<double, D>& extent,
            const std::array<double, D>& h) {
    origin = o;
    num_nodes = num_cells = 1;
    for (int d = 0; d < D; ++d) {
      cells[d] = int(std::lround(extent[d] / h[d]));
      cell[d] = extent[d] / cells[d];  // exact fit of the extent
      inv_cell[d] = 1.0 / cell[d];
      nodes[d] = cells[d] + 1;
      cell_stride[d] = long(num_cells);
      num_cells *= size_t(cells[d]);
    }
    std::array<int, D> lo{};
    store_nodes(lo, nodes);
  }

  /// Store only the nodes [lo, hi) per axis (global indices): node indices then count that box.
  void store_nodes(const std::array<int, D>& lo, const std::array<int, D>& hi) {
    num_nodes = 1;
    for (int d = 0; d < D; ++d) {
      node_lo[d] = lo[d];
      box_nodes[d] = hi[d] - lo[d];
      node_stride[d] = long(num_nodes);
      num_nodes *= size_t(box_nodes[d]);
    }
  }
  /// Whether the node with global indices ijk is in the stored box (always serially).
  bool stores(const std::array<int, D>& ijk) const {
    for (int d = 0; d < D; ++d)
      if (ijk[d] < node_lo[d] || ijk[d] >= node_lo[d] + box_nodes[d]) return false;
    return true;
  }
  /// Index of the stored node with global indices ijk (inside the box).
  size_t node_index(const std::array<int, D>& ijk) const {
    size_t n = 0;
    for (int d = 0; d < D; ++d) n += size_t(ijk[d] - node_lo[d]) * size_t(node_stride[d]);
    return n;
  }

  double min_cell() const {
    double h = cell[0];
    for (int d = 1; d < D; ++d) h = std::fmin(h, cell[d]);
    return h;
  }
  double upper(int d) const { return origin[d] + cells[d] * cell[d]; }

  /// Global indices of stored node n.
  std::array<int, D> node_ijk(size_t n) const {
    std::array<int, D> ijk{};
    for (int d = 0; d < D; ++d) {
      ijk[d] = int(n % size_t(box_nodes[d])) + node_lo[d];
      n /= size_t(box_nodes[d]);
    }
    return ijk;
  }
  double node_coord(size_t n, int d) const { return origin[d] + node_ijk(n)[d] * cell[d]; }

  /// Cell index along axis d of a coordinate, clamped into the grid.
  int cell_of(double x, int d) const {
    int c = int(std::floor((x - origin[d]) * inv_cell[d]));
    return c < 0 ? 0 : (c >= cells[d] ? cells[d] - 1 : c);
  }
  size_t cell_index(const std::array<double, D>& x) const {
    size_t c = 0;
    for (int d = 0; d < D; ++d) c += size_t(cell_of(x[d], d)) * size_t(cell_stride[d]);
    return c;
  }
  std::array<double, D> upper_corner() const {
    std::array<double, D> u{};
    for (int d = 0; d < D; ++d) u[d] = upper(d);
    return u;
  }
  /// Whether the box [lo, hi] lies inside the grid (to 1e-12 m: corners written on a face).
  bool holds_box(const std::array<double, D>& lo, const std::array<double, D>& hi) const {
    for (int d = 0; d < D; ++d)
      if (!(lo[d] >= origin[d] - 1e-12 && hi[d] <= upper(d) + 1e-12)) return false;
    return true;
  }
  bool inside(const std::array<double, D>& x) const {
    for (int d = 0; d < D; ++d)
      if (!(x[d] >= origin[d] && x[d] <= upper(d))) return false;
    return true;
  }
};

/// A D-vector stored per node inside an interleaved node record:
/// component d of node n is base[n*stride + offset + d].
struct NodalVector {
  double* base;
  int stride;
  int offset;
  double& at(size_t n, int d) const { return base[n * size_t(stride) + size_t(offset + d)]; }
};

}  // namespace loam
