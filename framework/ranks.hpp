#pragma once
// The ranks a run is split over (docs/parallel.md). A run on one process has one rank, and every
// operation here is then the identity: the serial code path does exactly what it did before.
// Under `mpirun`, the MPI build's MpiRanks (framework/mpi/mpi_ranks.hpp) splits the grid into
// Cartesian blocks: each rank keeps the particles of its cells and a box of nodes (its own and
// a ghost layer as wide as the shape function's reach), completes its nodal sums with the
// neighbouring blocks after every scatter, hands particles over after the move, and reduces the
// step's scalars (time step, energies, failures) over all ranks. The core and the schemes call
// only this interface; the MPI code lives in libloam_mpi.
#include <algorithm>
#include <array>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "grid.hpp"
#include "particles.hpp"

namespace loam {

/// "_rRRRR": names rank r's file among the ranks' files of one output.
std::string rank_tag(int rank);

/// A nodal array as the exchanges see it: node n's `width` values start at
/// data[n * stride + offset] (a scheme's interleaved record, or one field of it).
struct NodalArray {
  double* data;
  int stride, width, offset = 0;
};

template <int D>
class Ranks {
 public:
  virtual ~Ranks() = default;
  /// Whether the run is split by a parallel launcher (mpirun), also at one rank: then the
  /// features that do not run on ranks yet are refused (Simulation's build).
  virtual bool distributed() const { return false; }
  virtual int rank() const { return 0; }
  /// Whether the grid has been split (decompose succeeded): each rank then holds only its own
  /// cells' particles. Before, or when the model has errors, every rank holds all of them.
  virtual bool split() const { return false; }
  virtual int size() const { return 1; }
  bool root() const { return rank() == 0; }
  /// What ends the name of this rank's own file of an output split over the ranks (its piece
  /// of a frame, its checkpoint): rank_tag(rank()) under mpirun, "" serially.
  std::string file_tag() const { return distributed() ? rank_tag(rank()) : ""; }

  /// Split the grid: this rank's box of nodes is stored in `grid` (Grid::store_nodes), which
  /// must outlive the ranks; `threads` pack and unpack the messages. Returns "" or why the grid
  /// cannot be split over these ranks (a block thinner than the shape function's reach).
  /// No block boundary cuts an axis with whole[d] (a periodic axis: each rank holds both its
  /// faces and joins them itself).
  virtual std::string decompose(Grid<D>& /*grid*/, int /*rows_below*/, int /*rows_above*/,
                                int /*threads*/, const std::array<bool, D>& /*whole*/) {
    return "";
  }
  /// This rank's block of grid cells, [lo, hi) per axis, where the block sits in the array of
  /// blocks and that array's size. The particles of these cells are generated and kept here.
  struct CellBlock {
    std::array<int, D> lo{}, hi{}, coord{}, dims{};
  };
  /// Serially (or before the grid is split): the whole grid, one block.
  virtual CellBlock cell_block(const Grid<D>& grid) const {
    CellBlock b;
    b.hi = grid.cells;
    b.dims.fill(1);
    return b;
  }
  /// Whether this rank owns grid node ijk (global indices): the lower corners of its cells,
  /// and the last node row along an axis for the last block along it.
  bool owns_node(const Grid<D>& grid, const std::array<int, D>& ijk) const {
    const CellBlock b = cell_block(grid);
    for (size_t d = 0; d < size_t(D); ++d) {
      const int hi = b.coord[d] == b.dims[d] - 1 ? b.hi[d] + 1 : b.hi[d];
      if (ijk[d] < b.lo[d] || ijk[d] >= hi) return false;
    }
    return true;
  }

  /// Complete nodal sums over the ranks after a scatter: each ghost node's share is added into
  /// its owner (in a fixed neighbour order), and the owner's total copied back to every ghost
  /// copy, so that every stored node holds the whole grid's value (a reverse and a forward halo
  /// exchange, each one packed message per neighbour).
  virtual void complete_nodes(const std::vector<NodalArray>& /*arrays*/) {}
  /// Complete sums over grid cells (K values per cell, global cell index) after the move and
  /// before migration: a particle is then in an owned cell or in the ghost layer of one cell
  /// around the block. The ghost cells' shares are added into their owners and the totals
  /// copied back, so every cell a particle of this rank is in holds the whole model's sum.
  virtual void complete_cells(double* /*sums*/, int /*K*/) {}
  /// Send the particles of P whose cell another rank owns to it, append those that arrive.
  /// Returns whether P changed (a particle left or arrived). `strays` counts the particles that
  /// moved beyond the neighbouring blocks (kept here; `first_stray` is the first one's id).
  virtual bool migrate(Particles<D>& /*P*/, long& strays, long& first_stray) {
    strays = 0;
    first_stray = -1;
    return false;
  }

  /// Reductions over all ranks (every rank calls them, in the same order).
  virtual double min(double v) const { return v; }
  virtual double max(double v) const { return v; }
  virtual void sum(double* /*values*/, int /*n*/) const {}
  /// Element-wise maxima of n values over the ranks, in place.
  virtual void max(double* /*values*/, int /*n*/) const {}
  virtual int max(int v) const { return v; }
  /// The message of the lowest rank whose message is not empty, on every rank ("" if none):
  /// a failure one rank finds stops every rank, with the same words.
  virtual std::string first_message(const std::string& mine) const { return mine; }
  /// Every rank's n, on rank 0 in rank order (empty on the others).
  virtual std::vector<long> gather(long n) const { return {n}; }
  /// Every rank's values, concatenated in rank order, on rank 0 (empty on the others).
  virtual std::vector<double> gather(const std::vector<double>& mine) const { return mine; }
  /// Every rank's values, concatenated in rank order, on every rank.
  virtual std::vector<double> all_gather(const std::vector<double>& mine) const { return mine; }
  virtual void barrier() const {}
};

/// Reduce the given numbers over all ranks in place with `reduce(double*, n)`, one call for all
/// of them (every rank passes the same list). Counts go through doubles, exact below 2^53.
template <class Reduce, class... T>
void reduce_over_ranks(Reduce&& reduce, T&... values) {
  double all[] = {double(values)...};
  reduce(all, int(sizeof...(T)));
  size_t k = 0;
  ((values = T(all[k++])), ...);
}
/// Sums over all ranks of the given numbers, in place: sum_over_ranks(ranks, volume, count).
template <int D, class... T>
void sum_over_ranks(const Ranks<D>& ranks, T&... values) {
  reduce_over_ranks([&](double* v, int n) { ranks.sum(v, n); }, values...);
}
/// Maxima over all ranks of the given numbers, in place (as sum_over_ranks).
template <int D, class... T>
void max_over_ranks(const Ranks<D>& ranks, T&... values) {
  reduce_over_ranks([&](double* v, int n) { ranks.max(v, n); }, values...);
}

/// Per item, the candidate whose first `key` values are lexicographically smallest over all
/// ranks: each rank gives n items of `width` values (the key, then values carried along; a rank
/// without a candidate for an item puts +inf first). Every rank gets the n winners (collective;
/// serially `mine`). Picks "the particle nearest to a point, of equally near ones the first in
/// the serial order" (setup_order) whichever rank holds it.
template <int D>
std::vector<double> smallest_over_ranks(const Ranks<D>& ranks, const std::vector<double>& mine,
                                        int width, int key) {
  const std::vector<double> all = ranks.all_gather(mine);
  std::vector<double> best(all.begin(), all.begin() + long(mine.size()));  // the first rank's
  for (size_t r = 1; r * mine.size() < all.size(); ++r)
    for (size_t k = 0; k < mine.size(); k += size_t(width)) {
      const double* c = &all[r * mine.size() + k];
      if (std::lexicographical_compare(c, c + key, &best[k], &best[k] + key))
        std::copy(c, c + width, &best[k]);
    }
  return best;
}

/// Particle i's place in its set's order right after set-up, as a key of three doubles:
/// (material, cell, id). Partition::sort is a stable sort by material and cell of particles
/// generated in id order, so in a serial run this order is the index order, and under mpirun it
/// is the same for a particle whichever rank holds it.
template <int D>
std::array<double, 3> setup_order(const Particles<D>& P, const Grid<D>& grid, size_t i) {
  std::array<double, D> x{};
  for (int d = 0; d < D; ++d) x[size_t(d)] = P.col(P.position, d)[i];
  return {double(P.material[i]), double(grid.cell_index(x)), double(P.id[i])};
}

/// Makes the ranks of a run of dimension D. Empty (the default): the serial Ranks. The MPI
/// build's main sets these when the process was started by mpirun.
struct RanksFactory {
  std::function<std::unique_ptr<Ranks<1>>()> d1;
  std::function<std::unique_ptr<Ranks<2>>()> d2;
  std::function<std::unique_ptr<Ranks<3>>()> d3;
};
RanksFactory& ranks_factory();

template <int D>
std::unique_ptr<Ranks<D>> make_ranks() {
  const RanksFactory& f = ranks_factory();
  if constexpr (D == 1) {
    if (f.d1) return f.d1();
  } else if constexpr (D == 2) {
    if (f.d2) return f.d2();
  } else {
    if (f.d3) return f.d3();
  }
  return std::make_unique<Ranks<D>>();
}

}  // namespace loam
