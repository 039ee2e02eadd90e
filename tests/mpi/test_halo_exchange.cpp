// The halo exchange under mpirun (framework/mpi/halo_exchange.hpp; docs/parallel.md), run by
// ctest at 1, 2 and 4 ranks: every rank scatters the particles of its cells (P2G's mass,
// momentum and force, plus a second array of another layout) onto its box of nodes; after the
// reverse exchange every owned node holds the serial scatter's value to 1e-12 of the field's
// largest value, after the forward exchange every ghost does too; the whole sequence repeated
// gives the same bits; each particle is owned by exactly one rank; one message per neighbour
// and exchange. In 1D, 2D and 3D with linear, gimp and bspline2 (the ghost layer follows the
// reach). Rank 0 prints the measured numbers (tests/mpi/main.cpp runs it).
#include <mpi.h>

#include <cmath>
#include <cstdio>
#include <cstring>

#include "../decomposition_scene.hpp"
#include "framework/mpi/cartesian_ranks.hpp"
#include "framework/mpi/halo_exchange.hpp"
#include "mpi_check.hpp"

namespace loam_mpi_test {

namespace {

/// Largest |local - serial| over the nodes `which` walks, per component, relative to the
/// component's largest |serial| value over the grid.
template <int D>
double max_relative_error(const loam::Grid<D>& g, const loam::NodeBox<D>& box,
                          const loam::NodeBox<D>& which, const std::vector<double>& local,
                          const std::vector<double>& serial, int width) {
  std::vector<double> scale(size_t(width), 0.0);
  for (size_t n = 0; n < g.num_nodes; ++n)
    for (int c = 0; c < width; ++c)
      scale[size_t(c)] =
          std::fmax(scale[size_t(c)], std::fabs(serial[n * size_t(width) + size_t(c)]));
  double e = 0;
  which.for_each([&](const std::array<int, D>& ijk) {
    size_t n = 0;
    for (int d = 0; d < D; ++d) n += size_t(ijk[d]) * size_t(g.node_stride[size_t(d)]);
    const size_t l = box.local_index(ijk);
    for (int c = 0; c < width; ++c) {
      const double s = scale[size_t(c)] > 0 ? scale[size_t(c)] : 1.0;
      e = std::fmax(e, std::fabs(local[l * size_t(width) + size_t(c)] -
                                 serial[n * size_t(width) + size_t(c)]) /
                           s);
    }
  });
  return e;
}

template <int D>
void halo_case(const std::string& shape) {
  constexpr int S = 1 + 2 * D;
  const int size = loam_mpi_test::size(), g_rank = rank();
  auto sim = loam_test::decomposition_scene<D>(shape);
  const auto& g = sim->grid;
  const loam::CartesianRanks<D> ranks(MPI_COMM_WORLD);
  const MPI_Comm cart = ranks.comm();
  const auto& dims = ranks.dims();
  const auto& coords = ranks.coords();
  const loam::Decomposition<D> dec(g, dims, coords, sim->shape->rows_below(),
                                   sim->shape->rows_above());
  loam::HaloExchange<D> halo(cart, dec, 2);

  // The serial scatter of every particle onto the whole grid: the reference.
  loam::NodeBox<D> all;
  for (int d = 0; d < D; ++d) all.hi[size_t(d)] = g.nodes[size_t(d)];
  const auto serial = loam_test::scatter_to_box<D>(*sim, all, [](const auto&) { return true; });

  std::vector<std::vector<double>> runs;
  double owned_error = 0, extra_error = 0, box_error = 0;
  long outside = 0, owned_particles = 0;
  for (int run = 0; run < 2; ++run) {
    owned_particles = 0;
    auto local = loam_test::scatter_to_box<D>(*sim, dec.box(), [&](const std::array<int, D>& c) {
      const bool mine = dec.owns_cell(c);
      owned_particles += mine;
      return mine;
    });
    outside = local.outside;
    const std::vector<loam::NodalArray> arrays{{local.record.data(), S, S, 0},
                                               {local.extra.data(), 2, 2, 0}};
    halo.reverse(arrays);
    owned_error = max_relative_error<D>(g, dec.box(), dec.owned(), local.record, serial.record, S);
    extra_error = max_relative_error<D>(g, dec.box(), dec.owned(), local.extra, serial.extra, 2);
    halo.forward(arrays);
    box_error =
        std::fmax(max_relative_error<D>(g, dec.box(), dec.box(), local.record, serial.record, S),
                  max_relative_error<D>(g, dec.box(), dec.box(), local.extra, serial.extra, 2));
    local.record.insert(local.record.end(), local.extra.begin(), local.extra.end());
    runs.push_back(std::move(local.record));
  }
  const bool same_bits = runs[0].size() == runs[1].size() &&
                         std::memcmp(runs[0].data(), runs[1].data(), runs[0].size() * 8) == 0;

  // Each particle owned by exactly one rank.
  const long total = global_sum(owned_particles);
  const long n_particles = long(sim->sets[0].particles.size());
  // One message per neighbour and exchange: 4 exchanges (two runs, reverse and forward).
  const long messages = halo.messages_sent();
  const bool one_per_neighbour = messages == 4L * halo.neighbours();
  long max_messages = 0, max_bytes = 0, out_all = 0;
  MPI_Allreduce(&messages, &max_messages, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  const long bytes = halo.bytes_sent();
  MPI_Allreduce(&bytes, &max_bytes, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(&outside, &out_all, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  owned_error = global_max(owned_error);
  extra_error = global_max(extra_error);
  box_error = global_max(box_error);

  const std::string name = std::to_string(D) + "D " + shape + ", " + std::to_string(size) +
                           " ranks (" + dims_name(dims) + ")";
  if (g_rank == 0)
    std::printf(
        "%-32s owned nodes after reverse: %.1e (record), %.1e (second array); every box node "
        "after forward: %.1e; repeat same bits: %s; particles owned %ld of %ld; entries outside "
        "the box %ld; per rank and exchange at most %.1f messages, %.0f bytes\n",
        name.c_str(), owned_error, extra_error, box_error, same_bits ? "yes" : "NO", total,
        n_particles, out_all, double(max_messages) / 4, double(max_bytes) / 4);
  const double tol = 1e-12;  // relative to the field's largest value: round-off of the sums
  check(owned_error <= tol && extra_error <= tol, name + ": owned nodes equal the serial scatter");
  check(box_error <= tol, name + ": ghosts equal their owners after the forward exchange");
  check(same_bits, name + ": a repeated exchange gives the same bits");
  check(total == n_particles, name + ": every particle owned exactly once");
  check(out_all == 0, name + ": every stencil entry inside the rank's box");
  check(one_per_neighbour, name + ": one message per neighbour and exchange");
}

}  // namespace

void halo_exchange_tests() {
  for (const std::string shape : {"linear", "gimp", "bspline2"}) {
    halo_case<1>(shape);
    halo_case<2>(shape);
    halo_case<3>(shape);
  }
}

}  // namespace loam_mpi_test
