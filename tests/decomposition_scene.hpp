#pragma once
// The scene and the particle-to-grid scatter the decomposition tests share (the serial checks of
// framework/decomposition.hpp in tests/test_decomposition.cpp and the mpirun tests of the halo
// exchange in tests/mpi/): a grid of uneven cell counts per axis filled with particles, moved
// off the regular lattice (some onto cell faces), with velocities and stresses that differ per
// particle; and a scatter of mass, momentum and force (P2G's formulas) plus a second array onto
// the nodes of a box, from the particles in the cells a block owns. No Catch here: the MPI test
// has its own main.
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "framework/config.hpp"
#include "framework/decomposition.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam_test {

/// 23 cells in 1D, 13 x 11 in 2D, 7 x 6 x 5 in 3D (h = 0.1 m), filled with particles (2 per cell
/// and axis), shape function `shape`.
template <int D>
std::unique_ptr<loam::Simulation<D>> decomposition_scene(const std::string& shape) {
  static const double extent[3][3] = {{2.3, 0, 0}, {1.3, 1.1, 0}, {0.7, 0.6, 0.5}};
  auto vec = [](const double* v) {
    std::string s = "[";
    for (int d = 0; d < D; ++d) s += (d ? ", " : "") + std::to_string(v[d]);
    return s + "]";
  };
  const double zero[3] = {0, 0, 0};
  const std::string yaml = "grid: {extent: " + vec(extent[D - 1]) +
                           ", cell_size: 0.1}\nshape_function: " + shape +
                           "\nbodies:\n  - name: b\n    generator: {type: box, min: " + vec(zero) +
                           ", max: " + vec(extent[D - 1]) +
                           "}\n    particles_per_cell: 2\n"
                           "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: "
                           "1000}\ntime: {end: 1}\n";
  loam::Diagnostics diag;
  loam::LoadedConfig cfg = loam::load_config_text(yaml, "<decomposition scene>", {}, diag);
  if (!diag.ok()) throw std::runtime_error(diag.format());
  auto sim = std::make_unique<loam::Simulation<D>>(cfg.params, 1, diag);
  if (!diag.ok()) throw std::runtime_error(diag.format());
  // Off the lattice by up to 0.2 h away from the grid faces (GIMP domains stay inside), every
  // seventh interior particle onto a cell face along x; velocities and stresses per particle.
  auto& P = sim->sets[0].particles;
  const auto& g = sim->grid;
  for (size_t i = 0; i < P.size(); ++i) {
    bool interior = true;
    for (int d = 0; d < D; ++d) {
      const double x = P.col(P.position, d)[i];
      interior = interior && x > g.origin[size_t(d)] + 0.1 && x < g.upper(d) - 0.1;
    }
    for (int d = 0; d < D; ++d) {
      double& x = P.col(P.position, d)[i];
      if (interior) x += 0.02 * std::sin(1.3 * double(i) + d);
      if (interior && d == 0 && i % 7 == 0) x = std::round(x / 0.1) * 0.1;
      P.col(P.velocity, d)[i] = std::sin(0.7 * double(i) + d);
    }
    for (int c = 0; c < loam::Particles<D>::NS; ++c)
      P.col(P.stress, c)[i] = 1e3 * std::cos(0.3 * double(i) + c);
  }
  return sim;
}

/// Nodal arrays over a box: `record` holds mass, momentum (D) and force (D) per node
/// (1 + 2D values), `extra` two more values (w V and w V id), as a second array of another
/// layout would.
struct BoxArrays {
  std::vector<double> record, extra;
  long outside = 0;  // stencil entries of non-zero weight or gradient outside the box
};

/// P2G from the particles whose cell `owns` accepts, onto the nodes of `box`.
template <int D, class Owns>
BoxArrays scatter_to_box(loam::Simulation<D>& sim, const loam::NodeBox<D>& box, Owns&& owns) {
  constexpr int S = 1 + 2 * D;
  BoxArrays out;
  out.record.assign(box.size() * S, 0.0);
  out.extra.assign(box.size() * 2, 0.0);
  const auto& P = sim.sets[0].particles;
  const auto& g = sim.grid;
  loam::StencilBlock<D> st;
  st.allocate(sim.shape->max_nodes_per_particle());
  for (size_t b = 0; b < P.size(); b += loam::kBlock) {
    const int count = int(std::min<size_t>(loam::kBlock, P.size() - b));
    sim.shape->evaluate(g, P, b, count, st);
    for (int p = 0; p < count; ++p) {
      const size_t i = b + size_t(p);
      std::array<int, D> cell{};
      for (int d = 0; d < D; ++d) cell[size_t(d)] = g.cell_of(P.col(P.position, d)[i], d);
      if (!owns(cell)) continue;
      const double m = P.col(P.mass)[i], V = P.col(P.volume)[i];
      for (int k = 0; k < st.npp; ++k) {
        const size_t kp = size_t(k) * loam::kBlock + size_t(p);
        const double w = st.w[kp];
        double grad[D];
        bool zero = w == 0.0;
        for (int j = 0; j < D; ++j) {
          grad[j] = st.grad[(size_t(k) * D + size_t(j)) * loam::kBlock + size_t(p)];
          zero = zero && grad[j] == 0.0;
        }
        if (zero) continue;  // entries beyond the grid: a valid index, nothing to add
        const auto ijk = g.node_ijk(size_t(st.node[kp]));
        if (!box.contains(ijk)) {
          ++out.outside;
          continue;
        }
        const size_t n = box.local_index(ijk);
        double* r = out.record.data() + n * S;
        r[0] += w * m;
        for (int d = 0; d < D; ++d) {
          r[1 + d] += w * m * P.col(P.velocity, d)[i];
          double f = w * m * sim.gravity[size_t(d)];
          for (int j = 0; j < D; ++j)
            f -= V * P.col(P.stress, loam::voigt_index(d, j))[i] * grad[j];
          r[1 + D + d] += f;
        }
        out.extra[n * 2] += w * V;
        out.extra[n * 2 + 1] += w * V * double(P.id[i]);
      }
    }
  }
  return out;
}

}  // namespace loam_test
