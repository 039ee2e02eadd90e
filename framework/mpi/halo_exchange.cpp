#include "halo_exchange.hpp"

#include <stdexcept>
#include <string>

#include "mpi_error.hpp"

namespace loam {

namespace {

int values_per_node(const std::vector<NodalArray>& arrays) {
  int n = 0;
  for (const auto& a : arrays) n += a.width;
  return n;
}

/// Copy the values of `nodes` (every array, node-major) into buf.
void pack(const std::vector<NodalArray>& arrays, const std::vector<size_t>& nodes, double* buf,
          int per_node, int threads) {
  const long n = long(nodes.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (n > 4096)
  for (long i = 0; i < n; ++i) {
    double* out = buf + size_t(i) * size_t(per_node);
    for (const auto& a : arrays) {
      const double* v = a.data + nodes[size_t(i)] * size_t(a.stride) + size_t(a.offset);
      for (int c = 0; c < a.width; ++c) *out++ = v[c];
    }
  }
}

/// Add (or copy) buf into the values of `nodes`.
void unpack(const std::vector<NodalArray>& arrays, const std::vector<size_t>& nodes,
            const double* buf, int per_node, bool add, int threads) {
  const long n = long(nodes.size());
#pragma omp parallel for schedule(static) num_threads(threads) if (n > 4096)
  for (long i = 0; i < n; ++i) {
    const double* in = buf + size_t(i) * size_t(per_node);
    for (const auto& a : arrays) {
      double* v = a.data + nodes[size_t(i)] * size_t(a.stride) + size_t(a.offset);
      for (int c = 0; c < a.width; ++c) v[c] = add ? v[c] + *in++ : *in++;
    }
  }
}

}  // namespace

template <int D>
HaloExchange<D>::HaloExchange(MPI_Comm comm, const Decomposition<D>& decomposition, int threads)
    : HaloExchange(comm, decomposition.neighbours(), threads) {}

template <int D>
HaloExchange<D>::HaloExchange(MPI_Comm comm,
                              const std::vector<typename Decomposition<D>::Neighbour>& links,
                              int threads)
    : comm_(comm), threads_(threads) {
  for (const auto& n : links) {
    Link l;
    mpi_check(MPI_Cart_rank(comm, n.coords.data(), &l.rank), "MPI_Cart_rank");
    l.send_tag = direction_tag<D>(n.offset, 1);   // this rank -> neighbour: travelling by +offset
    l.recv_tag = direction_tag<D>(n.offset, -1);  // neighbour -> this rank: travelling by -offset
    l.ghosts = &n.ghosts;
    l.shared = &n.shared;
    links_.push_back(std::move(l));
  }
}

template <int D>
void HaloExchange<D>::exchange(const std::vector<NodalArray>& arrays, bool reverse) {
  const int per_node = values_per_node(arrays);
  std::vector<MPI_Request> requests(2 * links_.size(), MPI_REQUEST_NULL);
  // Reverse: ghosts go out, owned (shared) nodes come in; forward: the other way round.
  for (size_t i = 0; i < links_.size(); ++i) {
    Link& l = links_[i];
    const auto& in = reverse ? *l.shared : *l.ghosts;
    l.recv.resize(in.size() * size_t(per_node));
    mpi_check(MPI_Irecv(l.recv.data(), int(l.recv.size()), MPI_DOUBLE, l.rank, l.recv_tag, comm_,
                        &requests[2 * i]),
              "MPI_Irecv");
  }
  for (size_t i = 0; i < links_.size(); ++i) {
    Link& l = links_[i];
    const auto& out = reverse ? *l.ghosts : *l.shared;
    l.send.resize(out.size() * size_t(per_node));
    pack(arrays, out, l.send.data(), per_node, threads_);
    mpi_check(MPI_Isend(l.send.data(), int(l.send.size()), MPI_DOUBLE, l.rank, l.send_tag, comm_,
                        &requests[2 * i + 1]),
              "MPI_Isend");
    messages_ += 1;
    bytes_ += long(l.send.size() * sizeof(double));
  }
  mpi_check(MPI_Waitall(int(requests.size()), requests.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
  // In the fixed neighbour order: the owners' sums are the same bits on every run.
  for (const Link& l : links_)
    unpack(arrays, reverse ? *l.shared : *l.ghosts, l.recv.data(), per_node, reverse, threads_);
}

template <int D>
void HaloExchange<D>::reverse(const std::vector<NodalArray>& arrays) {
  exchange(arrays, true);
}

template <int D>
void HaloExchange<D>::forward(const std::vector<NodalArray>& arrays) {
  exchange(arrays, false);
}

template class HaloExchange<1>;
template class HaloExchange<2>;
template class HaloExchange<3>;

}  // namespace loam
