#pragma once
// Consistency checks shared by the shape-function tests: evaluate every particle's stencil and
// measure |sum N - 1|, h |sum grad N|, |sum N x_I - x_p| / h, |sum x_I (x) grad N - I|, and
// stencil entries outside the node rows [r - rows_below, r + rows_above] the shape function
// declares for race-free scatter (must be 0), and non-finite weights or gradients (must be 0).
#include <algorithm>
#include <array>
#include <catch2/catch.hpp>
#include <cmath>
#include <map>

#include "framework/simulation.hpp"

namespace loam_test {

struct StencilErrors {
  double sum = 0, grad = 0, repro = 0, grad_repro = 0, rows = 0, nonfinite = 0;

  /// The worst of both (the counts add up).
  void merge(const StencilErrors& o) {
    sum = std::max(sum, o.sum), grad = std::max(grad, o.grad);
    repro = std::max(repro, o.repro), grad_repro = std::max(grad_repro, o.grad_repro);
    rows += o.rows, nonfinite += o.nonfinite;
  }
};

/// Evaluate every particle (in full blocks) and measure the consistency errors: |sum N - 1|,
/// h |sum grad N|, |sum N x_I - x_p| / h, |sum x_I (x) grad N - I|, and stencil entries outside
/// the node rows [r - rows_below, r + rows_above] (must be 0), and non-finite weights or gradient
/// components (must be 0).
template <int D>
StencilErrors stencil_consistency(loam::Simulation<D>& sim) {
  auto& P = sim.sets[0].particles;
  const auto& g = sim.grid;
  loam::StencilBlock<D> st;
  st.allocate(sim.shape->nodes_per_particle());
  StencilErrors e;
  for (size_t b = 0; b < P.size(); b += loam::kBlock) {
    const int count = int(std::min<size_t>(loam::kBlock, P.size() - b));
    sim.shape->evaluate(g, P, b, count, st);
    for (int p = 0; p < count; ++p) {
      double sum = 0, gsum[D] = {}, xr[D] = {}, gx[D][D] = {};
      const int row = g.cell_of(P.col(P.position, D - 1)[b + size_t(p)], D - 1);
      for (int k = 0; k < st.npp; ++k) {
        const size_t kp = size_t(k) * loam::kBlock + size_t(p);
        REQUIRE(st.node[kp] >= 0);
        REQUIRE(size_t(st.node[kp]) < g.num_nodes);
        const int node_row = g.node_ijk(size_t(st.node[kp]))[D - 1];
        if (node_row < row - sim.shape->rows_below() || node_row > row + sim.shape->rows_above())
          e.rows += 1;
        if (!std::isfinite(st.w[kp])) e.nonfinite += 1;
        for (int j = 0; j < D; ++j)
          if (!std::isfinite(st.grad[(size_t(k) * D + size_t(j)) * loam::kBlock + size_t(p)]))
            e.nonfinite += 1;
        sum += st.w[kp];
        for (int i = 0; i < D; ++i) {
          const double xi = g.node_coord(size_t(st.node[kp]), i);
          xr[i] += st.w[kp] * xi;
          for (int j = 0; j < D; ++j)
            gx[i][j] += xi * st.grad[(size_t(k) * D + size_t(j)) * loam::kBlock + size_t(p)];
        }
        for (int j = 0; j < D; ++j)
          gsum[j] += st.grad[(size_t(k) * D + size_t(j)) * loam::kBlock + size_t(p)];
      }
      e.sum = std::max(e.sum, std::fabs(sum - 1));
      for (int i = 0; i < D; ++i) {
        e.grad = std::max(e.grad, std::fabs(gsum[i]) * g.cell[size_t(i)]);
        e.repro = std::max(
            e.repro, std::fabs(xr[i] - P.col(P.position, i)[b + size_t(p)]) / g.cell[size_t(i)]);
        for (int j = 0; j < D; ++j)
          e.grad_repro = std::max(e.grad_repro, std::fabs(gx[i][j] - (i == j ? 1.0 : 0.0)));
      }
    }
  }
  return e;
}

/// The affine transfers' geometry a tensor-product shape function gives from its axis values
/// (StencilBlock::affine, framework/axis_stencil.hpp) against the same from the node coordinates:
/// offsets x_I - x_p that differ from Grid::node_coord - x_p in any bit, max |D_dd / D^-1 - 1| and
/// max |D_de| / (h_d h_e) (d != e) of D_p = sum_k N_k dx_k dx_k^T, stencil entries whose node,
/// weight or gradient differ from the plain evaluation, and whether the shape function filled
/// them at all.
struct AffineGeometryErrors {
  double offsets = 0, inertia = 0, off_diagonal = 0, changed = 0;
  bool filled = true;
};

template <int D>
AffineGeometryErrors affine_geometry_errors(loam::Simulation<D>& sim) {
  auto& P = sim.sets[0].particles;
  const auto& g = sim.grid;
  loam::StencilBlock<D> plain, st;
  plain.allocate(sim.shape->nodes_per_particle());
  st.allocate(sim.shape->nodes_per_particle());
  AffineGeometryErrors e;
  for (size_t b = 0; b < P.size(); b += loam::kBlock) {
    const int count = int(std::min<size_t>(loam::kBlock, P.size() - b));
    sim.shape->evaluate(g, P, b, count, plain);
    st.affine = loam::StencilBlock<D>::kInertia;
    sim.shape->evaluate(g, P, b, count, st);
    e.filled = e.filled && st.has_affine;
    if (!st.has_affine) continue;
    for (int p = 0; p < count; ++p) {
      double Dp[D][D] = {};
      for (int k = 0; k < st.npp; ++k) {
        const size_t kp = size_t(k) * loam::kBlock + size_t(p);
        bool same = st.node[kp] == plain.node[kp] && st.w[kp] == plain.w[kp];
        double dx[D];
        for (int d = 0; d < D; ++d) {
          const size_t kdp = (size_t(k) * D + size_t(d)) * loam::kBlock + size_t(p);
          same = same && st.grad[kdp] == plain.grad[kdp];
          dx[d] = g.node_coord(size_t(st.node[kp]), d) - P.col(P.position, d)[b + size_t(p)];
          if (st.offset(k, d, p) != dx[d]) e.offsets += 1;
        }
        if (!same) e.changed += 1;
        for (int d = 0; d < D; ++d)
          for (int j = 0; j < D; ++j) Dp[d][j] += st.w[kp] * dx[d] * dx[j];
      }
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) {
          if (d == j)
            e.inertia = std::max(
                e.inertia,
                std::fabs(Dp[d][d] * st.inertia_inv[size_t(d) * loam::kBlock + size_t(p)] - 1));
          else
            e.off_diagonal = std::max(
                e.off_diagonal, std::fabs(Dp[d][j]) / (g.cell[size_t(d)] * g.cell[size_t(j)]));
        }
    }
  }
  return e;
}

/// Weight and gradient per node of one particle, summed over stencil entries (entries for nodes
/// outside the grid map to a valid node with zero weight, and CPDI repeats nodes, so summing is
/// exact).
template <int D>
using NodeValues = std::map<int32_t, std::array<double, D + 1>>;

template <int D>
NodeValues<D> node_values(loam::Simulation<D>& sim, size_t particle) {
  loam::StencilBlock<D> st;
  st.allocate(sim.shape->nodes_per_particle());
  sim.shape->evaluate(sim.grid, sim.sets[0].particles, particle, 1, st);
  NodeValues<D> out;
  for (int k = 0; k < st.npp; ++k) {
    const size_t kp = size_t(k) * loam::kBlock;
    REQUIRE(st.node[kp] >= 0);
    REQUIRE(size_t(st.node[kp]) < sim.grid.num_nodes);
    auto& v = out[st.node[kp]];
    v[0] += st.w[kp];
    for (int d = 0; d < D; ++d)
      v[size_t(d + 1)] += st.grad[(size_t(k) * D + size_t(d)) * loam::kBlock];
  }
  return out;
}

}  // namespace loam_test
