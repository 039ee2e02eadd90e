#pragma once
// The ranks of a run under mpirun (framework/ranks.hpp, docs/parallel.md): a Cartesian block
// decomposition of the grid (framework/decomposition.hpp), the packed halo exchange
// (halo_exchange.hpp) and the particle migration (particle_migration.hpp) behind the interface
// the core and the schemes call, and the step's reductions over MPI_COMM_WORLD's Cartesian
// communicator. Only the master thread calls MPI (MPI_THREAD_FUNNELED).
#include <mpi.h>

#include <memory>

#include "cartesian_ranks.hpp"
#include "framework/decomposition.hpp"
#include "framework/ranks.hpp"
#include "halo_exchange.hpp"
#include "particle_migration.hpp"

namespace loam {

template <int D>
class MpiRanks : public Ranks<D> {
 public:
  explicit MpiRanks(MPI_Comm world) : cart_(world) {}

  bool distributed() const override { return true; }
  int rank() const override { return cart_.rank(); }
  int size() const override { return cart_.size(); }
  const CartesianRanks<D>& cartesian() const { return cart_; }
  const HaloExchange<D>* halo() const { return halo_.get(); }
  const ParticleMigration<D>* migration() const { return migration_.get(); }

  std::string decompose(Grid<D>& grid, int rows_below, int rows_above, int threads,
                        const std::array<bool, D>& whole) override;
  typename Ranks<D>::CellBlock cell_block(const Grid<D>& grid) const override;
  bool split() const override { return decomposition_ != nullptr; }
  void complete_nodes(const std::vector<NodalArray>& arrays) override;
  void complete_cells(double* sums, int K) override;
  bool migrate(Particles<D>& P, long& strays, long& first_stray) override;

  double min(double v) const override;
  double max(double v) const override;
  int max(int v) const override;
  void sum(double* values, int n) const override;
  void max(double* values, int n) const override;
  std::string first_message(const std::string& mine) const override;
  std::vector<long> gather(long n) const override;
  std::vector<double> gather(const std::vector<double>& mine) const override;
  std::vector<double> all_gather(const std::vector<double>& mine) const override;
  void barrier() const override;

 private:
  /// MPI_Allreduce of one value over the ranks.
  template <class T>
  T all_reduce(T v, MPI_Datatype type, MPI_Op op) const;

  CartesianRanks<D> cart_;
  const Grid<D>* grid_ = nullptr;
  std::unique_ptr<Decomposition<D>> decomposition_;
  std::unique_ptr<HaloExchange<D>> halo_;
  std::vector<typename Decomposition<D>::Neighbour> cell_links_;
  std::unique_ptr<HaloExchange<D>> cell_halo_;
  std::unique_ptr<ParticleMigration<D>> migration_;
};

/// Stop every rank (MPI_Abort): a rank that cannot go on while the others wait.
[[noreturn]] void mpi_abort(int code);

/// MPI_Init_thread (FUNNELED) and the ranks factory of framework/ranks.hpp, for a process that
/// a parallel launcher started; MPI_Finalize when it goes out of scope.
class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  int rank_ = 0, size_ = 1;
};

}  // namespace loam
