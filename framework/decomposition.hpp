#pragma once
// Cartesian block decomposition of the grid over ranks (docs/parallel.md): the ranks
// form a dims[0] x ... x dims[D-1] array (MPI_Dims_create / MPI_Cart_create), and rank `coords`
// owns the cells [cell_lo, cell_hi) of its block, the particles in them (of every set) and the
// nodes that are the lower corners of its cells (the last block along an axis also owns the
// grid's last node row). Its nodal arrays cover the owned nodes plus a ghost layer as wide as
// the shape function's reach: a particle in cell row r touches node rows [r - rows_below,
// r + rows_above] (ShapeFunction), so the local box is [cell_lo - rows_below, cell_hi - 1 +
// rows_above], clipped to the grid. Ghost nodes are owned by the immediate neighbours (the 3^D - 1
// blocks around, diagonals included) as long as every block is at least as wide as the ghost
// layer; a thinner block is refused with the reason. What a rank sends to and receives from each
// neighbour is the intersection of node boxes, walked in the same order (x fastest) on both
// sides, so the packed buffers match without sending node ids.
//
// No MPI here: the halo exchange that uses it is framework/mpi/halo_exchange.hpp.
#include <algorithm>
#include <array>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "grid.hpp"

namespace loam {

/// [lo, hi) of part `index` of n items split into `parts` contiguous parts whose sizes differ by
/// at most one (the first n % parts parts one larger).
inline std::pair<int, int> split_range(int n, int parts, int index) {
  const int base = n / parts, extra = n % parts;
  const int lo = index * base + std::min(index, extra);
  return {lo, lo + base + (index < extra ? 1 : 0)};
}

/// The 3^D - 1 offsets of the blocks around one (each component -1, 0 or 1; diagonals
/// included), in a fixed order: the order in which neighbours are served.
template <int D>
std::vector<std::array<int, D>> neighbour_offsets() {
  std::vector<std::array<int, D>> offsets;
  int count = 1;
  for (int d = 0; d < D; ++d) count *= 3;
  for (int o = 0; o < count; ++o) {
    std::array<int, D> off{};
    bool self = true;
    for (int d = 0, r = o; d < D; ++d, r /= 3) {
      off[size_t(d)] = r % 3 - 1;
      self = self && off[size_t(d)] == 0;
    }
    if (!self) offsets.push_back(off);
  }
  return offsets;
}

/// The tag of a message travelling by `offset` from sender to receiver (sign -1: by -offset,
/// what a receiver expects from its neighbour at `offset`), 0 .. 3^D - 1.
template <int D>
int direction_tag(const std::array<int, D>& offset, int sign) {
  int t = 0;
  for (int d = D - 1; d >= 0; --d) t = 3 * t + (sign * offset[size_t(d)] + 1);
  return t;
}

/// A box of grid nodes [lo, hi) per axis (global node indices), walked x fastest.
template <int D>
struct NodeBox {
  std::array<int, D> lo{}, hi{};

  bool empty() const {
    for (int d = 0; d < D; ++d)
      if (hi[d] <= lo[d]) return true;
    return false;
  }
  size_t size() const {
    if (empty()) return 0;
    size_t n = 1;
    for (int d = 0; d < D; ++d) n *= size_t(hi[d] - lo[d]);
    return n;
  }
  bool contains(const std::array<int, D>& ijk) const {
    for (int d = 0; d < D; ++d)
      if (ijk[d] < lo[d] || ijk[d] >= hi[d]) return false;
    return true;
  }
  NodeBox intersect(const NodeBox& o) const {
    NodeBox r;
    for (int d = 0; d < D; ++d) {
      r.lo[d] = std::max(lo[d], o.lo[d]);
      r.hi[d] = std::min(hi[d], o.hi[d]);
    }
    return r;
  }
  /// Index of node ijk (inside) in an array laid out over this box, x fastest.
  size_t local_index(const std::array<int, D>& ijk) const {
    size_t i = 0, stride = 1;
    for (int d = 0; d < D; ++d) {
      i += size_t(ijk[d] - lo[d]) * stride;
      stride *= size_t(hi[d] - lo[d]);
    }
    return i;
  }
  /// f(ijk) for every node, x fastest.
  template <class F>
  void for_each(F&& f) const {
    if (empty()) return;
    std::array<int, D> ijk = lo;
    for (;;) {
      f(ijk);
      int d = 0;
      while (d < D && ++ijk[d] == hi[d]) ijk[d] = lo[d], ++d;
      if (d == D) return;
    }
  }
};

template <int D>
class Decomposition {
 public:
  /// A block next to this one: its offset (components -1, 0, 1) and rank coordinates.
  struct Adjacent {
    std::array<int, D> offset{}, coords{};
  };
  /// One neighbouring block and the nodes the two share: `ghosts`, nodes of this rank's box the
  /// neighbour owns (sent to it by the reverse exchange, received by the forward one), and
  /// `shared`, owned nodes inside the neighbour's box (received, then sent). Local indices into
  /// this rank's box, in the order both sides walk them.
  struct Neighbour : Adjacent {
    std::vector<size_t> ghosts, shared;
  };

  /// Rank `coords` of a dims-block decomposition of `grid`, ghost layers for a shape function
  /// reaching rows_below / rows_above node rows (ShapeFunction). std::invalid_argument, with
  /// the reason, for a block narrower than its ghost layer or more blocks than cells.
  Decomposition(const Grid<D>& grid, const std::array<int, D>& dims,
                const std::array<int, D>& coords, int rows_below, int rows_above)
      : dims_(dims), coords_(coords), below_(rows_below), above_(rows_above) {
    const int width = std::max(rows_below, rows_above);
    for (int d = 0; d < D; ++d) {
      cells_[d] = grid.cells[d];
      if (dims[d] < 1 || coords[d] < 0 || coords[d] >= dims[d])
        throw std::invalid_argument("rank coordinates outside the rank array");
      if (cells_[d] / dims[d] < width) {
        std::string why = "the grid has " + std::to_string(cells_[d]) + " cells along ";
        why += "xyz"[d];
        why += " for " + std::to_string(dims[d]) + " ranks: a block needs at least " +
               std::to_string(width) +
               " cells (the shape function's reach); use fewer ranks or a finer grid";
        throw std::invalid_argument(why);
      }
    }
    owned_ = owned_of(coords);
    box_ = box_of(coords);
    find_neighbours();
  }

  const std::array<int, D>& dims() const { return dims_; }
  const std::array<int, D>& coords() const { return coords_; }
  /// Cells [lo, hi) of block c along axis d.
  std::pair<int, int> cells_of(const std::array<int, D>& c, int d) const {
    return split_range(cells_[d], dims_[d], c[d]);
  }
  /// Whether this rank owns cell ijk (and so the particles in it).
  bool owns_cell(const std::array<int, D>& ijk) const {
    for (int d = 0; d < D; ++d) {
      const auto [lo, hi] = cells_of(coords_, d);
      if (ijk[d] < lo || ijk[d] >= hi) return false;
    }
    return true;
  }
  /// The nodes block c owns.
  NodeBox<D> owned_of(const std::array<int, D>& c) const {
    NodeBox<D> b;
    for (int d = 0; d < D; ++d) {
      const auto [lo, hi] = cells_of(c, d);
      b.lo[d] = lo;
      b.hi[d] = c[d] == dims_[d] - 1 ? hi + 1 : hi;  // the last block owns the last node row
    }
    return b;
  }
  /// Block c's owned nodes and ghost layer: the nodes its particles' stencils reach.
  NodeBox<D> box_of(const std::array<int, D>& c) const {
    NodeBox<D> b;
    for (int d = 0; d < D; ++d) {
      const auto [lo, hi] = cells_of(c, d);
      b.lo[d] = std::max(0, lo - below_);
      b.hi[d] = std::min(cells_[d] + 1, hi + above_);  // node rows up to hi - 1 + above
    }
    return b;
  }
  const NodeBox<D>& owned() const { return owned_; }
  const NodeBox<D>& box() const { return box_; }
  /// The neighbouring blocks that share nodes with this one, offsets in lexicographic order.
  const std::vector<Neighbour>& neighbours() const { return neighbours_; }
  /// Every block next to this one in the rank array (3^D - 1 at most, diagonals included;
  /// particles may cross into any of them), in neighbour_offsets' order.
  std::vector<Adjacent> adjacent_blocks() const {
    std::vector<Adjacent> blocks;
    for (const auto& offset : neighbour_offsets<D>()) {
      Adjacent a{offset, {}};
      bool inside = true;
      for (int d = 0; d < D; ++d) {
        a.coords[size_t(d)] = coords_[d] + offset[size_t(d)];
        inside = inside && a.coords[size_t(d)] >= 0 && a.coords[size_t(d)] < dims_[d];
      }
      if (inside) blocks.push_back(a);
    }
    return blocks;
  }

  /// Links for sums over grid cells (a scheme's per-cell means after the move): this block's
  /// cells and a ghost layer of one cell around them (a particle moves less than a cell per
  /// step, so before migration it is in an owned or a ghost cell). Per adjacent block, `ghosts`
  /// are the ghost cells it owns and `shared` the owned cells in its ghost layer, as global
  /// cell indices (`cell_stride`: the grid's), both walked in the same order on both sides.
  std::vector<Neighbour> cell_links(const std::array<long, D>& cell_stride) const {
    auto cells = [&](const std::array<int, D>& c, int layer) {
      NodeBox<D> b;
      for (int d = 0; d < D; ++d) {
        const auto [lo, hi] = cells_of(c, d);
        b.lo[d] = std::max(0, lo - layer);
        b.hi[d] = std::min(cells_[d], hi + layer);
      }
      return b;
    };
    auto index = [&](const std::array<int, D>& ijk) {
      size_t i = 0;
      for (int d = 0; d < D; ++d) i += size_t(ijk[d]) * size_t(cell_stride[d]);
      return i;
    };
    std::vector<Neighbour> links;
    for (const auto& a : adjacent_blocks()) {
      Neighbour n;
      n.offset = a.offset;
      n.coords = a.coords;
      cells(coords_, 1).intersect(cells(a.coords, 0)).for_each([&](const auto& ijk) {
        n.ghosts.push_back(index(ijk));
      });
      cells(coords_, 0).intersect(cells(a.coords, 1)).for_each([&](const auto& ijk) {
        n.shared.push_back(index(ijk));
      });
      if (!n.ghosts.empty() || !n.shared.empty()) links.push_back(std::move(n));
    }
    return links;
  }

 private:
  std::array<int, D> dims_, coords_, cells_{};
  int below_, above_;
  NodeBox<D> owned_, box_;
  std::vector<Neighbour> neighbours_;

  void find_neighbours() {
    for (const auto& a : adjacent_blocks()) {
      Neighbour n;
      n.offset = a.offset;
      n.coords = a.coords;
      box_.intersect(owned_of(n.coords)).for_each([&](const std::array<int, D>& ijk) {
        n.ghosts.push_back(box_.local_index(ijk));
      });
      owned_.intersect(box_of(n.coords)).for_each([&](const std::array<int, D>& ijk) {
        n.shared.push_back(box_.local_index(ijk));
      });
      if (!n.ghosts.empty() || !n.shared.empty()) neighbours_.push_back(std::move(n));
    }
  }
};

}  // namespace loam
