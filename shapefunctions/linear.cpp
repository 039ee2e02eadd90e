// Linear (tent) shape functions on the cell containing the particle: 2^D nodes, C0 across cell
// faces (the source of cell-crossing noise that GIMP, CPDI and B-splines remove).
#include "framework/axis_stencil.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Linear : public ShapeFunction<D> {
 public:
  static constexpr const char* name = "linear";
  static constexpr const char* summary = "linear tent functions on the particle's cell (2^D nodes)";
  static Schema schema() { return Schema(); }
  explicit Linear(const Params&) {}

  int nodes_per_particle() const override { return 1 << D; }
  int rows_below() const override { return 0; }
  int rows_above() const override { return 1; }
  /// Node rows fixed by the particle's cell: the ghost layer is rows_below / rows_above wide.
  bool runs_on_ranks() const override { return true; }
  bool stencil_covers_domain() const override { return false; }

  void evaluate(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                StencilBlock<D>& out) const override {
    constexpr int K = 1 << D;
    out.count = count;
    // Per-axis weights first (vectorises across particles), then the 2^D tensor products,
    // node-major so that each inner loop runs over contiguous particles.
    alignas(64) double n[D][2][kBlock];  // the two nodes' axis weights
    alignas(64) int32_t base[kBlock];
    const bool affine = out.affine != StencilBlock<D>::kNone;
    for (int p = 0; p < count; ++p) base[p] = 0;
    for (int d = 0; d < D; ++d) {
      const double* x = P.col(P.position, d) + begin;
      const double o = g.origin[size_t(d)], ih = g.inv_cell[size_t(d)];
      const int last = g.cells[d] - 1;
      const int32_t stride = int32_t(g.node_stride[d]), lo = g.node_lo[size_t(d)];
      double* __restrict dx0 = affine ? axis_offsets(out, 2, d, 0) : nullptr;
      double* __restrict dx1 = affine ? axis_offsets(out, 2, d, 1) : nullptr;
      for (int p = 0; p < count; ++p) {
        const double xi = (x[p] - o) * ih;
        int c = int(xi);
        c = c < 0 ? 0 : (c > last ? last : c);  // stay inside the grid
        const double r = xi - c;
        n[d][0][p] = 1.0 - r;
        n[d][1][p] = r;
        base[p] += (c - lo) * stride;  // the stored box's index (Grid)
        if (affine) {  // the offsets, node coordinates as Grid::node_coord forms them
          dx0[p] = (o + double(c) * g.cell[size_t(d)]) - x[p];
          dx1[p] = (o + double(c + 1) * g.cell[size_t(d)]) - x[p];
        }
      }
    }
    axis_affine_product<D, 2>(count, n, out);
    for (int k = 0; k < K; ++k) {
      int32_t offset = 0;
      for (int d = 0; d < D; ++d) offset += (k >> d) & 1 ? int32_t(g.node_stride[d]) : 0;
      int32_t* node = out.node.data() + size_t(k) * kBlock;
      double* w = out.w.data() + size_t(k) * kBlock;
      for (int p = 0; p < count; ++p) {
        node[p] = base[p] + offset;
        double wp = 1.0;
        for (int d = 0; d < D; ++d) wp *= n[d][(k >> d) & 1][p];
        w[p] = wp;
      }
      for (int d = 0; d < D; ++d) {
        // dN/dx_d = (+-1/h_d) * product of the other axes' weights
        const double sign_ih = ((k >> d) & 1 ? 1.0 : -1.0) * g.inv_cell[size_t(d)];
        double* gr = out.grad.data() + (size_t(k) * D + size_t(d)) * kBlock;
        for (int p = 0; p < count; ++p) {
          double gp = sign_ih;
          for (int e = 0; e < D; ++e)
            if (e != d) gp *= n[e][(k >> e) & 1][p];
          gr[p] = gp;
        }
      }
    }
  }
};

LOAM_REGISTER_DEFAULT(ShapeFunction, Linear)

}  // namespace loam
