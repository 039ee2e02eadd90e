// Linear (tent) shape functions on the cell containing the particle: 2^D nodes, C0 across cell
// faces (the source of cell-crossing noise that GIMP, CPDI and B-splines remove).
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

  void evaluate(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                StencilBlock<D>& out) const override {
    constexpr int K = 1 << D;
    out.count = count;
    std::array<const double*, D> x{};
    for (int d = 0; d < D; ++d) x[size_t(d)] = P.col(P.position, d) + begin;
    for (int p = 0; p < count; ++p) {
      double n0[D], n1[D];
      long base = 0;
      for (int d = 0; d < D; ++d) {
        const double xi = (x[size_t(d)][p] - g.origin[size_t(d)]) * g.inv_cell[size_t(d)];
        int c = int(xi);
        c = c < 0 ? 0 : (c >= g.cells[d] ? g.cells[d] - 1 : c);  // stay inside the grid
        const double r = xi - c;
        n0[d] = 1.0 - r;
        n1[d] = r;
        base += long(c) * g.node_stride[d];
      }
      for (int k = 0; k < K; ++k) {
        long node = base;
        double w = 1.0;
        for (int d = 0; d < D; ++d) {
          const bool up = (k >> d) & 1;
          node += up ? g.node_stride[d] : 0;
          w *= up ? n1[d] : n0[d];
        }
        const size_t kp = size_t(k) * kBlock + size_t(p);
        out.node[kp] = int32_t(node);
        out.w[kp] = w;
        for (int d = 0; d < D; ++d) {
          // dN/dx_d = (+-1/h_d) * product of the other axes' weights
          double gd = ((k >> d) & 1 ? 1.0 : -1.0) * g.inv_cell[size_t(d)];
          for (int e = 0; e < D; ++e)
            if (e != d) gd *= (k >> e) & 1 ? n1[e] : n0[e];
          out.grad[(size_t(k) * D + size_t(d)) * kBlock + size_t(p)] = gd;
        }
      }
    }
  }
};

LOAM_REGISTER_DEFAULT(ShapeFunction, Linear)

}  // namespace loam
