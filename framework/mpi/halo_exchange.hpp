#pragma once
// The halo exchange of nodal quantities between the blocks of a Cartesian decomposition
// (docs/parallel.md "Halo exchange"; framework/decomposition.hpp):
//   reverse: every rank sends the values its particles scattered onto ghost nodes to the
//            neighbour that owns them, every nodal array of every phase packed in one buffer per
//            neighbour; the owner adds what it receives in a fixed neighbour order (offsets in
//            lexicographic order), so the sums are the same bits on every run at a given rank
//            count (equal to the serial scatter to round-off: the order of the additions differs);
//   forward: every owner sends its (updated) values of the nodes its neighbours hold as ghosts.
// One message per neighbour and direction, point to point (no MPI_ANY_SOURCE, no Allreduce over
// shared nodes); packing and unpacking run under OpenMP, only the calling (master) thread talks
// to MPI (MPI_THREAD_FUNNELED).
#include <mpi.h>

#include <vector>

#include "framework/decomposition.hpp"
#include "framework/ranks.hpp"  // NodalArray

namespace loam {

template <int D>
class HaloExchange {
 public:
  /// `comm`: the Cartesian communicator whose rank coordinates `decomposition` was built for;
  /// `decomposition` must outlive the exchange (its links hold the node lists).
  HaloExchange(MPI_Comm comm, const Decomposition<D>& decomposition, int threads = 1);
  /// The same over other links, e.g. Decomposition::cell_links for sums over cells (the arrays
  /// are then indexed by global cell); `links` must outlive the exchange.
  HaloExchange(MPI_Comm comm, const std::vector<typename Decomposition<D>::Neighbour>& links,
               int threads = 1);

  /// Ghost values added to their owners' (ghosts keep theirs; a forward exchange refreshes them).
  void reverse(const std::vector<NodalArray>& arrays);
  /// Owners' values copied to the ghosts that mirror them.
  void forward(const std::vector<NodalArray>& arrays);
  /// Sums completed over the ranks: reverse, then forward, so that every stored copy holds the
  /// total (what a scheme needs after a scatter; Ranks::complete_nodes).
  void complete(const std::vector<NodalArray>& arrays) {
    reverse(arrays);
    forward(arrays);
  }

  /// Messages and bytes this rank has sent, over every exchange so far.
  long messages_sent() const { return messages_; }
  long bytes_sent() const { return bytes_; }
  int neighbours() const { return int(links_.size()); }

 private:
  struct Link {
    int rank, send_tag, recv_tag;
    const std::vector<size_t>* ghosts;
    const std::vector<size_t>* shared;
    std::vector<double> send, recv;
  };
  MPI_Comm comm_;
  int threads_;
  std::vector<Link> links_;
  long messages_ = 0, bytes_ = 0;

  /// One message to and from every neighbour: reverse sends the ghosts and adds into the shared
  /// (owned) nodes, forward sends the shared nodes and overwrites the ghosts.
  void exchange(const std::vector<NodalArray>& arrays, bool reverse);
};

}  // namespace loam
