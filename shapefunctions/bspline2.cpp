// Quadratic B-splines on the uniform grid (Steffen, Kirby & Berzins 2008, IJNME 76 922-948), with
// the boundary-modified functions of de Vaucorbeil, Nguyen, Sinaie & Wu 2020 ("Material point
// method after 25 years", Adv. Appl. Mech. 53, section 3; also their code Karamelo), so that
// partition of unity and linear reproduction hold up to the grid boundary without ghost nodes.
//
// Interior: the node-centred quadratic B-spline, with u = (x_p - x_I)/h,
//   N(u) = 3/4 - u^2                 |u| < 1/2
//        = (3/2 - |u|)^2 / 2         1/2 <= |u| < 3/2
//        = 0                         otherwise,
// C1 everywhere; its knots are at cell centres, so N is smooth across cell faces. A particle at
// r = (x_p - x_b)/h in [-1/2, 1/2) from its nearest node b touches nodes b-1, b, b+1 (3^D entries)
// with weights (r - 1/2)^2/2, 3/4 - r^2, (r + 1/2)^2/2 and gradients (r - 1/2)/h, -2r/h,
// (r + 1/2)/h.
//
// Boundary: the missing ghost node -1 beyond boundary node 0 is eliminated by extrapolating it
// linearly, N_0 <- N_0 + 2 N_-1 and N_1 <- N_1 - N_-1 (the constants and linear functions take
// the values 1 = 2*1 - 1 and x_-1 = 2 x_0 - x_1 at the ghost, so both stay reproduced exactly);
// likewise at the last node n: N_n <- N_n + 2 N_n+1, N_n-1 <- N_n-1 - N_n+1. This gives exactly
// the modified functions of de Vaucorbeil et al. (2020), for the boundary node (x in [x_0, x_0 +
// 3h/2), t = (x - x_0)/h)
//   N_0 = 1 - t                      0 <= t < 1/2
//       = (3/2 - t)^2 / 2            1/2 <= t < 3/2
// and for its neighbour (t = (x - x_0)/h, x in [x_0, x_0 + 5h/2))
//   N_1 = t                          0 <= t < 1/2
//       = 3/4 - (t - 1)^2            1/2 <= t < 3/2
//       = (5/2 - t)^2 / 2            3/2 <= t < 5/2,
// all non-negative and C1. Half a cell next to the boundary the basis is the linear one.
// Stencil entries whose node is outside the grid (the ghosts) carry the nearest valid node index
// and zero weight and gradient.
#include <algorithm>
#include <cmath>

#include "framework/axis_stencil.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class BSpline2 : public ShapeFunction<D> {
 public:
  static constexpr const char* name = "bspline2";
  static constexpr const char* summary =
      "quadratic B-splines (3^D nodes, C1), boundary-modified so that partition of unity and "
      "linear reproduction hold up to the grid boundary";
  static Schema schema() { return Schema(); }
  explicit BSpline2(const Params&) {}

  int nodes_per_particle() const override { return ipow(3, D); }
  /// Gradients linear inside a cell: the stable pressure per cell is linear (Q2-P1disc).
  CellPressure cell_pressure() const override { return CellPressure::kLinear; }
  // Nearest node b is r or r+1 for a particle in cell row r; nodes b-1 .. b+1.
  int rows_below() const override { return 1; }
  int rows_above() const override { return 2; }
  /// Node rows fixed by the particle's cell: the ghost layer is rows_below / rows_above wide.
  bool runs_on_ranks() const override { return true; }

  /// int N_i dx / h of the boundary-modified functions: the interior B-spline centred at i
  /// clipped to [0, last], plus its share of the folded ghosts. 13/24 and 23/24 for the first
  /// two nodes of a long axis, 1 inside.
  double axis_node_volume(int i, int last) const override {
    return fold_ghosts(
        i, last, [&](int j) { return cumulative(double(last - j)) - cumulative(double(-j)); });
  }

  /// The lattice's midpoint sums integrate the interior B-spline exactly (its second derivative
  /// integrates to zero over each node's support), but not the boundary-modified ones: with 2
  /// points per cell 0.53125 and 0.96875 for the first two nodes against 13/24 and 23/24.
  double axis_node_lattice_volume(int i, int last, int points_per_cell) const override {
    const int ppc = points_per_cell;
    const double s = 1.0 / ppc;
    return fold_ghosts(i, last, [&](int j) {  // the lattice points in the support |u - j| < 3/2
      double sum = 0;
      for (int k = std::max(0, (j - 2) * ppc); k < std::min(last, j + 2) * ppc; ++k)
        sum += weight((k + 0.5) * s - j);
      return sum * s;
    });
  }

  void evaluate(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                StencilBlock<D>& out) const override {
    constexpr int M = 3;
    out.count = count;
    // Per-axis weights first (vectorises across particles), then the tensor products.
    AxisStencil<D, M> ax;
    auto& w = ax.w;
    auto& dw = ax.dw;
    for (int d = 0; d < D; ++d) {
      const double* x = P.col(P.position, d) + begin;
      const double o = g.origin[size_t(d)], ih = g.inv_cell[size_t(d)];
      const int n = g.cells[d];  // last node index along d
      const double last = double(n);
      alignas(64) double bd[kBlock];
      for (int p = 0; p < count; ++p) {
        const double xi = (x[p] - o) * ih;
        int bi = int(xi + 0.5);  // nearest node, inside the grid
        bi = bi < 0 ? 0 : bi;
        bi = bi > n ? n : bi;
        const double b = double(bi);
        bd[p] = b;
        const double r = xi - b;
        const double w0 = 0.5 * (0.5 - r) * (0.5 - r), w1 = 0.75 - r * r,
                     w2 = 0.5 * (0.5 + r) * (0.5 + r);
        const double g0 = (r - 0.5) * ih, g1 = -2.0 * r * ih, g2 = (r + 0.5) * ih;
        // Fold the ghost node (b-1 = -1 or b+1 = n+1) into its two inner neighbours. The flags
        // lo = [b == 0] and hi = [b == n] are written as max(0, .) so that the loop vectorises.
        const double l1 = 1.0 - b, h1 = b - (last - 1.0);
        const double lo = l1 > 0.0 ? l1 : 0.0, hi = h1 > 0.0 ? h1 : 0.0;
        const double wg = lo * w0 + hi * w2, gg = lo * g0 + hi * g2;
        w[d][0][p] = w0 - wg;
        w[d][1][p] = w1 + 2.0 * wg;
        w[d][2][p] = w2 - wg;
        dw[d][0][p] = g0 - gg;
        dw[d][1][p] = g1 + 2.0 * gg;
        dw[d][2][p] = g2 - gg;
      }
      for (int p = 0; p < count; ++p) {
        const int b = int(bd[p]);
        ax.set_node(g, d, 0, p, b > 0 ? b - 1 : 0);
        ax.set_node(g, d, 1, p, b);
        ax.set_node(g, d, 2, p, b < n ? b + 1 : n);
      }
      ax.offsets(g, d, x, count, out);
    }
    ax.tensor_product(count, out);
  }

 private:
  /// of_node(j) applied to the boundary-modified function of node i, from its value for the
  /// interior B-splines centred at j: N_0 + 2 N_-1, N_1 - N_-1 and likewise at the last node.
  template <class F>
  static double fold_ghosts(int i, int last, F of_node) {
    double v = of_node(i);
    if (i == 0) v += 2 * of_node(-1);
    if (i == 1) v -= of_node(-1);
    if (i == last) v += 2 * of_node(last + 1);
    if (i == last - 1) v -= of_node(last + 1);
    return v;
  }

  /// The quadratic B-spline centred at 0, N(u).
  static double weight(double u) {
    const double a = std::fabs(u);
    if (a < 0.5) return 0.75 - a * a;
    if (a < 1.5) return 0.5 * (1.5 - a) * (1.5 - a);
    return 0.0;
  }

  /// int_-inf^u N(t) dt of the quadratic B-spline centred at 0 (support |t| < 3/2).
  static double cumulative(double u) {
    if (u <= -1.5) return 0.0;
    if (u <= -0.5) return (u + 1.5) * (u + 1.5) * (u + 1.5) / 6;
    if (u <= 0.5) return 1.0 / 6 + 0.75 * (u + 0.5) - (u * u * u + 0.125) / 3;
    if (u <= 1.5) return 1 - (1.5 - u) * (1.5 - u) * (1.5 - u) / 6;
    return 1.0;
  }
};

LOAM_REGISTER(ShapeFunction, BSpline2)

}  // namespace loam
