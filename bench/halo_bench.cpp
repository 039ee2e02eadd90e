// The halo exchange's cost per step (bench/RESULTS.md, docs/parallel.md): under mpirun, the 2D and 3D
// blocks of `loam bench` (160 x 176 cells, 24 x 24 x 24 cells), decomposed over the launched
// ranks with a ghost layer of gimp/bspline2 (rows 1 below, 2 above), and the exchanges one
// single-phase MUSL step makes: reverse and forward of the nodal record (mass, momentum, force:
// 1 + 2D values per node) and of the re-mapped momentum (D values). Prints per rank and step:
// messages, bytes, and the exchanges' wall time (median of 7 batches of 200 steps).
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <vector>

#include "framework/decomposition.hpp"
#include "framework/mpi/cartesian_ranks.hpp"
#include "framework/mpi/halo_exchange.hpp"

namespace {

template <int D>
void bench_block(const char* name, const std::array<int, D>& cells, double h) {
  loam::Grid<D> g;
  std::array<double, D> origin{}, extent{}, cell{};
  for (int d = 0; d < D; ++d) extent[size_t(d)] = cells[size_t(d)] * h, cell[size_t(d)] = h;
  g.init(origin, extent, cell);
  const loam::CartesianRanks<D> ranks(MPI_COMM_WORLD);
  const MPI_Comm cart = ranks.comm();
  const auto& dims = ranks.dims();
  const auto& coords = ranks.coords();
  const int rank = ranks.rank(), size = ranks.size();
  const loam::Decomposition<D> dec(g, dims, coords, 1, 2);
  loam::HaloExchange<D> halo(cart, dec, 1);
  constexpr int S = 1 + 2 * D;
  std::vector<double> record(dec.box().size() * S, 1.0), remap(dec.box().size() * D, 1.0);
  const std::vector<loam::NodalArray> rec{{record.data(), S, S, 0}}, vel{{remap.data(), D, D, 0}};
  auto step = [&] {
    halo.reverse(rec);
    halo.forward(rec);
    halo.reverse(vel);
    halo.forward(vel);
  };
  for (int i = 0; i < 50; ++i) step();  // warm-up
  const long m0 = halo.messages_sent(), b0 = halo.bytes_sent();
  std::vector<double> batches;
  constexpr int kSteps = 200;
  for (int b = 0; b < 7; ++b) {
    MPI_Barrier(cart);
    const double t0 = MPI_Wtime();
    for (int i = 0; i < kSteps; ++i) step();
    double t = (MPI_Wtime() - t0) / kSteps, tmax = 0;
    MPI_Allreduce(&t, &tmax, 1, MPI_DOUBLE, MPI_MAX, cart);
    batches.push_back(tmax);
  }
  std::sort(batches.begin(), batches.end());
  const double steps = 7.0 * kSteps;
  long msg = halo.messages_sent() - m0, bytes = halo.bytes_sent() - b0, msg_max = 0, bytes_max = 0;
  MPI_Allreduce(&msg, &msg_max, 1, MPI_LONG, MPI_MAX, cart);
  MPI_Allreduce(&bytes, &bytes_max, 1, MPI_LONG, MPI_MAX, cart);
  if (rank == 0) {
    std::printf("%-18s %d ranks (", name, size);
    for (int d = 0; d < D; ++d) std::printf("%s%d", d ? "x" : "", dims[size_t(d)]);
    std::printf(
        "): box %zu nodes, per rank and step at most %.0f messages, %.0f bytes; "
        "exchange time %.1f us (median of 7 x %d steps, slowest rank)\n",
        dec.box().size(), double(msg_max) / steps, double(bytes_max) / steps, batches[3] * 1e6,
        kSteps);
  }
}

}  // namespace

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  bench_block<2>("elastic_block_2d", {160, 176}, 0.00625);
  bench_block<3>("elastic_block_3d", {24, 24, 24}, 1.0 / 24);
  MPI_Finalize();
  return 0;
}
