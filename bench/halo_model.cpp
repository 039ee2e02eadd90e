// The weak-scaling model of the halo exchange (bench/RESULTS.md, docs/parallel.md): for a rank array of
// 2 to 64 ranks, each rank holding the `loam bench` block (2D: 160 x 176 cells, 102 400
// particles; 3D: 24 x 24 x 22 filled of 24^3 cells, 101 376 particles), the busiest rank's halo
// per single-phase MUSL step from the real decomposition (framework/decomposition.hpp; gimp's
// ghost layer: 1 row below, 2 above): messages (4 exchanges per neighbour) and bytes (the nodal
// record, 1 + 2D values, and the re-mapped momentum, D values, each way). With a network of
// latency alpha and bandwidth beta, t_comm = messages alpha + bytes / beta, against the step's
// particle work N t_p (t_p measured by loam bench, one thread). Also the block side at which
// t_comm would be 10 % of the step. Usage: loam_halo_model ALPHA_US BETA_GBS TP2D_NS TP3D_NS.
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "framework/decomposition.hpp"

namespace {

struct Halo {
  long messages = 0;
  double bytes = 0;
};

/// The busiest rank's halo per step for `dims` ranks of `block` cells each.
template <int D>
Halo halo(const std::array<int, D>& dims, const std::array<int, D>& block) {
  loam::Grid<D> g;
  std::array<double, D> o{}, e{}, h{};
  for (int d = 0; d < D; ++d) e[size_t(d)] = dims[size_t(d)] * block[size_t(d)], h[size_t(d)] = 1;
  g.init(o, e, h);
  Halo worst;
  loam::NodeBox<D> ranks;
  ranks.hi = dims;
  ranks.for_each([&](const std::array<int, D>& c) {
    const loam::Decomposition<D> dec(g, dims, c, 1, 2);
    long nodes = 0;
    for (const auto& l : dec.neighbours()) nodes += long(l.ghosts.size() + l.shared.size());
    Halo r{4L * long(dec.neighbours().size()), double(nodes) * (1 + 3 * D) * 8.0};
    if (r.bytes > worst.bytes) worst = r;
  });
  return worst;
}

template <int D>
void table(const char* name, const std::array<std::array<int, D>, 5>& arrays,
           std::array<int, D> block, double particles_per_cell, double alpha, double beta,
           double tp) {
  const double particles = D == 3 ? 101376 : 102400;
  const double step = particles * tp;
  std::printf("%s (%.0f particles per rank, step %.2f ms of particle work):\n", name, particles,
              step * 1e3);
  for (const auto& dims : arrays) {
    int ranks = 1;
    for (int d = 0; d < D; ++d) ranks *= dims[size_t(d)];
    const Halo hl = halo<D>(dims, block);
    const double t = double(hl.messages) * alpha + hl.bytes / beta;
    // The cubic block side s at which t_comm(s) = 10 % of s^D ppc t_p (bisection).
    double lo = 2, hi = 400;
    for (int it = 0; it < 40; ++it) {
      const double s = 0.5 * (lo + hi);
      std::array<int, D> b{};
      for (int d = 0; d < D; ++d) b[size_t(d)] = int(std::lround(s));
      const Halo hs = halo<D>(dims, b);
      const double comm = double(hs.messages) * alpha + hs.bytes / beta;
      const double work = std::pow(std::lround(s), D) * particles_per_cell * tp;
      (comm > 0.1 * work ? lo : hi) = s;
    }
    std::printf(
        "  %2d ranks: %3ld messages, %8.0f bytes per step; t_comm %6.1f us = %5.2f %% of the "
        "step; 10 %% at a block of %.0f^%d cells (%.0f particles per rank)\n",
        ranks, hl.messages, hl.bytes, t * 1e6, 100 * t / step, std::round(hi), D,
        std::pow(std::round(hi), D) * particles_per_cell);
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 5) {
    std::fprintf(stderr, "usage: %s ALPHA_US BETA_GBS TP2D_NS TP3D_NS\n", argv[0]);
    return 2;
  }
  const double alpha = std::atof(argv[1]) * 1e-6, beta = std::atof(argv[2]) * 1e9;
  const double tp2 = std::atof(argv[3]) * 1e-9, tp3 = std::atof(argv[4]) * 1e-9;
  std::printf("alpha %.1f us, beta %.1f GB/s, t_p %.0f ns (2D) and %.0f ns (3D)\n", alpha * 1e6,
              beta * 1e-9, tp2 * 1e9, tp3 * 1e9);
  table<2>("2D", {{{2, 1}, {4, 2}, {4, 4}, {8, 4}, {8, 8}}}, {160, 176}, 4, alpha, beta, tp2);
  table<3>("3D", {{{2, 1, 1}, {2, 2, 2}, {4, 2, 2}, {4, 4, 2}, {4, 4, 4}}}, {24, 24, 24}, 8, alpha,
           beta, tp3);
  return 0;
}
