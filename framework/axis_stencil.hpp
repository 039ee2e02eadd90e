#pragma once
// Tensor-product stencils: shape functions that are products of 1D functions (linear-like,
// GIMP, B-splines) fill per-axis weights, gradients and node offsets for a block of particles,
// then expand them into the StencilBlock node-major, so every inner loop runs over contiguous
// particles and vectorises.
#include "force_inline.hpp"
#include "shape_function.hpp"

namespace loam {

/// The affine transfers' geometry (StencilBlock::affine) of a tensor-product stencil whose
/// axis offsets the shape function has written into out.dx (entry k is node (k / M^d) % M
/// along axis d), from its axis weights w, for a block whose pass asked for it: sets
/// out.has_affine and, with kInertia, D_p^-1. For weights that are products of axis weights,
/// D_p = sum_k N_k dx_k dx_k^T factors into axis moments m_n(d) = sum_j w_dj dx_dj^n: D_dd =
/// m_2(d) prod_(e != d) m_0(e) and D_de = m_1(d) m_1(e) prod_(f != d, e) m_0(f). Partition of
/// unity (m_0 = 1) and linear reproduction (m_1 = 0) hold for the weights that use this
/// (linear, gimp and bspline2, their boundary-modified nodes included), so D_p = diag(m_2(d))
/// up to round-off (h^2/4 per axis for interior quadratic B-splines, as Jiang et al. 2015 give).
template <int D, int M>
void axis_affine_product(int count, const double (&w)[D][M][kBlock], StencilBlock<D>& out) {
  out.has_affine = out.affine != StencilBlock<D>::kNone;
  if (!out.has_affine) return;
  out.axis_nodes = M;
  if (out.affine != StencilBlock<D>::kInertia) return;
  for (int d = 0; d < D; ++d) {
    const double* dx = out.dx.data() + StencilBlock<D>::axis_offset_index(M, d, 0);
    double* __restrict inv = out.inertia_inv.data() + size_t(d) * kBlock;
    for (int p = 0; p < count; ++p) {
      double m2 = 0;
      for (int j = 0; j < M; ++j) m2 += w[d][j][p] * dx[j * kBlock + p] * dx[j * kBlock + p];
      inv[p] = 1.0 / m2;
    }
  }
}

/// Where a shape function writes x_I - x_p of axis node j along axis d in the stencil block
/// (StencilBlock::dx), with the node coordinate as Grid::node_coord forms it (origin + i h, i the
/// global index), so the offsets are the same bits as from the node coordinates, on a stored box
/// of nodes too.
template <int D>
LOAM_FORCE_INLINE double* axis_offsets(StencilBlock<D>& out, int M, int d, int j) {
  return out.dx.data() + StencilBlock<D>::axis_offset_index(M, d, j);
}

/// Per-axis weights, gradients and node offsets (node coordinate times stride) of M nodes for a
/// block of particles, and their tensor product into the stencil, node-major.
template <int D, int M>
struct AxisStencil {
  alignas(64) double w[D][M][kBlock];
  alignas(64) double dw[D][M][kBlock];
  alignas(64) int32_t node[D][M][kBlock];   // (i - node_lo) * node_stride: the stored box's
  alignas(64) int32_t index[D][M][kBlock];  // i: the node's global index along the axis

  /// Entry j of particle p along axis d is the node of global index i (clamped into the grid).
  LOAM_FORCE_INLINE void set_node(const Grid<D>& g, int d, int j, int p, int i) {
    index[d][j][p] = i;
    node[d][j][p] = (i - g.node_lo[size_t(d)]) * int32_t(g.node_stride[d]);
  }

  /// x_I - x_p along axis d of every axis node into the block, for the affine transfers
  /// (out.affine; axis_offsets).
  void offsets(const Grid<D>& g, int d, const double* x, int count, StencilBlock<D>& out) const {
    if (out.affine == StencilBlock<D>::kNone) return;
    const double o = g.origin[size_t(d)], h = g.cell[size_t(d)];
    for (int j = 0; j < M; ++j) {
      double* __restrict dx = axis_offsets(out, M, d, j);
      for (int p = 0; p < count; ++p) dx[p] = (o + double(index[d][j][p]) * h) - x[p];
    }
  }

  void tensor_product(int count, StencilBlock<D>& out) const {
    constexpr int K = ipow(M, D);
    axis_affine_product<D, M>(count, w, out);
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
