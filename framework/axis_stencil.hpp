#pragma once
// Tensor-product stencils: shape functions that are products of 1D functions (linear-like,
// GIMP, B-splines) fill per-axis weights, gradients and node offsets for a block of particles,
// then expand them into the StencilBlock node-major, so every inner loop runs over contiguous
// particles and vectorises.
#include "shape_function.hpp"

namespace loam {

/// Per-axis weights, gradients and node offsets (node coordinate times stride) of M nodes for a
/// block of particles, and their tensor product into the stencil, node-major.
template <int D, int M>
struct AxisStencil {
  alignas(64) double w[D][M][kBlock];
  alignas(64) double dw[D][M][kBlock];
  alignas(64) int32_t node[D][M][kBlock];

  void tensor_product(int count, StencilBlock<D>& out) const {
    constexpr int K = ipow(M, D);
    for (int k = 0; k < K; ++k) {
      // Entry k is node j[0] along x, j[1] along y, ...: N = prod_d w_d, dN/dx_d = dw_d prod_e!=d
      // w_e. One fused loop per entry (node, weight and gradients); the outputs are restrict:
      // they never overlap this block's per-axis arrays.
      const double* wa[D];
      const double* dwa[D];
      const int32_t* na[D];
      for (int d = 0, r = k; d < D; ++d, r /= M) {
        wa[d] = w[d][r % M];
        dwa[d] = dw[d][r % M];
        na[d] = node[d][r % M];
      }
      int32_t* __restrict node_k = out.node.data() + size_t(k) * kBlock;
      double* __restrict w_k = out.w.data() + size_t(k) * kBlock;
      double* __restrict grad_k = out.grad.data() + size_t(k) * D * kBlock;
      for (int p = 0; p < count; ++p) {
        int32_t n = 0;
        double wp = 1.0;
        for (int d = 0; d < D; ++d) {
          n += na[d][p];
          wp *= wa[d][p];
        }
        node_k[p] = n;
        w_k[p] = wp;
        for (int d = 0; d < D; ++d) {
          double gp = dwa[d][p];
          for (int e = 0; e < D; ++e)
            if (e != d) gp *= wa[e][p];
          grad_k[size_t(d) * kBlock + size_t(p)] = gp;
        }
      }
    }
  }
};

}  // namespace loam
