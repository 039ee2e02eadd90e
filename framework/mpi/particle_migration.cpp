#include "particle_migration.hpp"

#include <stdexcept>
#include <string>
#include <tuple>

#include "mpi_error.hpp"

namespace loam {

namespace {

/// The values a particle carries: every allocated field's components in registry order, then
/// id, material and body (integers below 2^53: exact as doubles).
template <int D>
int values_per_particle(const Particles<D>& P) {
  int n = 3;
  for (int f = 0; f < P.num_fields(); ++f)
    if (P.has(f)) n += P.info(f).components;
  return n;
}

template <int D>
void pack_particle(const Particles<D>& P, size_t i, std::vector<double>& out) {
  for (int f = 0; f < P.num_fields(); ++f)
    if (P.has(f))
      for (int c = 0; c < P.info(f).components; ++c) out.push_back(P.col(f, c)[i]);
  out.push_back(double(P.id[i]));
  out.push_back(double(P.material[i]));
  out.push_back(double(P.body[i]));
}

template <int D>
void unpack_particle(const double* in, Particles<D>& P, size_t i) {
  for (int f = 0; f < P.num_fields(); ++f)
    if (P.has(f))
      for (int c = 0; c < P.info(f).components; ++c) P.col(f, c)[i] = *in++;
  P.id[i] = uint32_t(in[0]);
  P.material[i] = uint16_t(in[1]);
  P.body[i] = uint16_t(in[2]);
}

}  // namespace

template <int D>
ParticleMigration<D>::ParticleMigration(MPI_Comm comm, const Decomposition<D>& decomposition,
                                        const Grid<D>& grid)
    : comm_(comm), dec_(decomposition), grid_(grid) {
  // Every immediate neighbour (not only those sharing nodes: a particle may cross a corner).
  for (const auto& a : dec_.adjacent_blocks()) {
    Link l;
    l.offset = a.offset;
    mpi_check(MPI_Cart_rank(comm, a.coords.data(), &l.rank), "MPI_Cart_rank");
    l.send_tag = direction_tag<D>(l.offset, 1);
    l.recv_tag = direction_tag<D>(l.offset, -1);
    links_.push_back(std::move(l));
  }
  for (int d = 0; d < D; ++d) std::tie(own_lo_[d], own_hi_[d]) = dec_.cells_of(dec_.coords(), d);
}

template <int D>
int ParticleMigration<D>::link_of(const std::array<int, D>& cell) const {
  std::array<int, D> offset{};
  bool self = true;
  for (int d = 0; d < D; ++d) {
    const auto [lo, hi] = dec_.cells_of(dec_.coords(), d);
    offset[d] = cell[d] < lo ? -1 : (cell[d] >= hi ? 1 : 0);
    self = self && offset[d] == 0;
    // Beyond the neighbour's block: further than one block away.
    if (offset[d] != 0) {
      std::array<int, D> nb = dec_.coords();
      nb[d] += offset[d];
      if (nb[d] < 0 || nb[d] >= dec_.dims()[d]) return -2;
      const auto [nlo, nhi] = dec_.cells_of(nb, d);
      if (cell[d] < nlo || cell[d] >= nhi) return -2;
    }
  }
  if (self) return -1;
  for (size_t k = 0; k < links_.size(); ++k)
    if (links_[k].offset == offset) return int(k);
  return -2;
}

template <int D>
bool ParticleMigration<D>::in_own_block(const Particles<D>& P, size_t i) const {
  for (int d = 0; d < D; ++d) {
    const int c = grid_.cell_of(P.col(P.position, d)[i], d);
    if (c < own_lo_[d] || c >= own_hi_[d]) return false;
  }
  return true;
}

template <int D>
long ParticleMigration<D>::migrate(Particles<D>& P) {
  const int per = values_per_particle(P);
  long strays = 0;
  first_stray_ = -1;
  for (auto& l : links_) l.send.clear();
  // Which particles leave: a threaded test against the own block (almost every particle stays),
  // then the leavers, in index order, packed by the master thread.
  const long n = long(P.size());
  long leaving_count = 0;
  leaving_.assign(P.size(), 0);
#pragma omp parallel for reduction(+ : leaving_count) schedule(static)
  for (long i = 0; i < n; ++i)
    if (!in_own_block(P, size_t(i))) leaving_[size_t(i)] = 1, ++leaving_count;
  for (long i = 0; leaving_count > 0 && i < n; ++i) {
    if (!leaving_[size_t(i)]) continue;
    std::array<int, D> cell{};
    for (int d = 0; d < D; ++d) cell[d] = grid_.cell_of(P.col(P.position, d)[size_t(i)], d);
    const int k = link_of(cell);
    if (k == -2) {  // kept here and reported: the other ranks are already on their way to receive
      if (strays == 0) first_stray_ = long(P.id[size_t(i)]);
      ++strays;
      leaving_[size_t(i)] = 0;
      continue;
    }
    pack_particle(P, size_t(i), links_[size_t(k)].send);
    particles_ += 1;
  }
  // Post every send (one per neighbour, empty ones included: the receiver waits for it), then
  // receive from each neighbour in the fixed order.
  std::vector<MPI_Request> sends(links_.size(), MPI_REQUEST_NULL);
  for (size_t k = 0; k < links_.size(); ++k) {
    Link& l = links_[k];
    mpi_check(MPI_Isend(l.send.data(), int(l.send.size()), MPI_DOUBLE, l.rank, l.send_tag, comm_,
                        &sends[k]),
              "MPI_Isend");
    messages_ += 1;
    bytes_ += long(l.send.size() * sizeof(double));
  }
  for (auto& l : links_) {
    MPI_Status status;
    mpi_check(MPI_Probe(l.rank, l.recv_tag, comm_, &status), "MPI_Probe");
    int count = 0;
    mpi_check(MPI_Get_count(&status, MPI_DOUBLE, &count), "MPI_Get_count");
    if (count % per != 0)
      throw std::runtime_error("particle migration: the ranks disagree on the particle fields");
    l.recv.resize(size_t(count));
    mpi_check(
        MPI_Recv(l.recv.data(), count, MPI_DOUBLE, l.rank, l.recv_tag, comm_, MPI_STATUS_IGNORE),
        "MPI_Recv");
  }
  mpi_check(MPI_Waitall(int(sends.size()), sends.data(), MPI_STATUSES_IGNORE), "MPI_Waitall");
  if (leaving_count > strays) P.erase(leaving_);
  size_t arriving = 0;
  for (const auto& l : links_) arriving += l.recv.size() / size_t(per);
  size_t i = P.size();
  P.resize(i + arriving);
  for (const auto& l : links_)
    for (size_t q = 0; q < l.recv.size(); q += size_t(per))
      unpack_particle(l.recv.data() + q, P, i++);
  return strays;
}

template class ParticleMigration<1>;
template class ParticleMigration<2>;
template class ParticleMigration<3>;

}  // namespace loam
