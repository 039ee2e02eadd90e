#include "mpi_ranks.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>
#include <tuple>

#include "mpi_error.hpp"

namespace loam {

template <int D>
std::string MpiRanks<D>::decompose(Grid<D>& grid, int rows_below, int rows_above, int threads,
                                   const std::array<bool, D>& whole) {
  if (!cart_.keep_whole(whole))
    return "the grid is periodic along every axis: no axis is left to split over " +
           std::to_string(cart_.size()) + " ranks (run it on one)";
  try {
    decomposition_ = std::make_unique<Decomposition<D>>(grid, cart_.dims(), cart_.coords(),
                                                        rows_below, rows_above);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  const NodeBox<D>& box = decomposition_->box();
  grid.store_nodes(box.lo, box.hi);
  grid_ = &grid;
  halo_ = std::make_unique<HaloExchange<D>>(cart_.comm(), *decomposition_, threads);
  cell_links_ = decomposition_->cell_links(grid.cell_stride);
  cell_halo_ = std::make_unique<HaloExchange<D>>(cart_.comm(), cell_links_, threads);
  migration_ = std::make_unique<ParticleMigration<D>>(cart_.comm(), *decomposition_, grid);
  return "";
}

template <int D>
typename Ranks<D>::CellBlock MpiRanks<D>::cell_block(const Grid<D>& grid) const {
  if (!decomposition_) return Ranks<D>::cell_block(grid);  // not split (the model has errors)
  typename Ranks<D>::CellBlock b;
  for (int d = 0; d < D; ++d)
    std::tie(b.lo[size_t(d)], b.hi[size_t(d)]) = decomposition_->cells_of(cart_.coords(), d);
  b.coord = cart_.coords();
  b.dims = cart_.dims();
  return b;
}

template <int D>
void MpiRanks<D>::complete_nodes(const std::vector<NodalArray>& arrays) {
  halo_->complete(arrays);
}

template <int D>
void MpiRanks<D>::complete_cells(double* sums, int K) {
  cell_halo_->complete({{sums, K, K}});
}

template <int D>
bool MpiRanks<D>::migrate(Particles<D>& P, long& strays, long& first_stray) {
  const long sent = migration_->particles_sent();
  const size_t before = P.size();
  strays = migration_->migrate(P);
  first_stray = migration_->first_stray();
  return migration_->particles_sent() != sent || P.size() != before;
}

template <int D>
template <class T>
T MpiRanks<D>::all_reduce(T v, MPI_Datatype type, MPI_Op op) const {
  T r = v;
  mpi_check(MPI_Allreduce(&v, &r, 1, type, op, cart_.comm()), "MPI_Allreduce");
  return r;
}

template <int D>
double MpiRanks<D>::min(double v) const {
  return all_reduce(v, MPI_DOUBLE, MPI_MIN);
}

template <int D>
double MpiRanks<D>::max(double v) const {
  return all_reduce(v, MPI_DOUBLE, MPI_MAX);
}

template <int D>
int MpiRanks<D>::max(int v) const {
  return all_reduce(v, MPI_INT, MPI_MAX);
}

template <int D>
void MpiRanks<D>::sum(double* values, int n) const {
  if (n > 0)
    mpi_check(MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_SUM, cart_.comm()),
              "MPI_Allreduce");
}

template <int D>
void MpiRanks<D>::max(double* values, int n) const {
  if (n > 0)
    mpi_check(MPI_Allreduce(MPI_IN_PLACE, values, n, MPI_DOUBLE, MPI_MAX, cart_.comm()),
              "MPI_Allreduce");
}

template <int D>
std::string MpiRanks<D>::first_message(const std::string& mine) const {
  const int first = all_reduce(mine.empty() ? cart_.size() : cart_.rank(), MPI_INT, MPI_MIN);
  if (first == cart_.size()) return "";
  int length = int(mine.size());
  mpi_check(MPI_Bcast(&length, 1, MPI_INT, first, cart_.comm()), "MPI_Bcast");
  std::string text = cart_.rank() == first ? mine : std::string(size_t(length), ' ');
  mpi_check(MPI_Bcast(text.data(), length, MPI_CHAR, first, cart_.comm()), "MPI_Bcast");
  return text;
}

template <int D>
std::vector<long> MpiRanks<D>::gather(long n) const {
  std::vector<long> all(cart_.rank() == 0 ? size_t(cart_.size()) : 0);
  mpi_check(MPI_Gather(&n, 1, MPI_LONG, all.data(), 1, MPI_LONG, 0, cart_.comm()), "MPI_Gather");
  return all;
}

template <int D>
std::vector<double> MpiRanks<D>::gather(const std::vector<double>& mine) const {
  const int n = int(mine.size());
  const bool root = cart_.rank() == 0;
  std::vector<int> counts(root ? size_t(cart_.size()) : 0), offsets(counts.size(), 0);
  mpi_check(MPI_Gather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, cart_.comm()), "MPI_Gather");
  for (size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(root ? size_t(offsets.back() + counts.back()) : 0);
  mpi_check(MPI_Gatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                        MPI_DOUBLE, 0, cart_.comm()),
            "MPI_Gatherv");
  return all;
}

template <int D>
std::vector<double> MpiRanks<D>::all_gather(const std::vector<double>& mine) const {
  const int n = int(mine.size());
  std::vector<int> counts(size_t(cart_.size())), offsets(size_t(cart_.size()), 0);
  mpi_check(MPI_Allgather(&n, 1, MPI_INT, counts.data(), 1, MPI_INT, cart_.comm()),
            "MPI_Allgather");
  for (size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  std::vector<double> all(size_t(offsets.back() + counts.back()));
  mpi_check(MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), offsets.data(),
                           MPI_DOUBLE, cart_.comm()),
            "MPI_Allgatherv");
  return all;
}

template <int D>
void MpiRanks<D>::barrier() const {
  mpi_check(MPI_Barrier(cart_.comm()), "MPI_Barrier");
}

template class MpiRanks<1>;
template class MpiRanks<2>;
template class MpiRanks<3>;

void mpi_abort(int code) {
  MPI_Abort(MPI_COMM_WORLD, code);
  std::exit(code);
}

MpiSession::MpiSession(int& argc, char**& argv) {
  int provided = 0;
  mpi_check(MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided), "MPI_Init_thread");
  if (provided < MPI_THREAD_FUNNELED)
    throw std::runtime_error("the MPI library does not provide MPI_THREAD_FUNNELED");
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  RanksFactory& f = ranks_factory();
  f.d1 = [] { return std::make_unique<MpiRanks<1>>(MPI_COMM_WORLD); };
  f.d2 = [] { return std::make_unique<MpiRanks<2>>(MPI_COMM_WORLD); };
  f.d3 = [] { return std::make_unique<MpiRanks<3>>(MPI_COMM_WORLD); };
}

MpiSession::~MpiSession() {
  ranks_factory() = RanksFactory{};
  MPI_Finalize();
}

}  // namespace loam
