// Uniform GIMP (generalized interpolation material point; Bardenhagen & Kober 2004, CMES 5(6)
// 477-495, the "uGIMP" of Wallstedt & Guilkey 2008, JCP 227 9628-9642). The weight of node I is
// the linear hat N_I averaged over the particle's domain, a box of half-width lp_d per axis:
//   S_I(x_p) = prod_d S(x_pd - x_Id; lp_d, h_d),  S(xi) = 1/(2 lp) int_{xi-lp}^{xi+lp} N(s) ds.
// For lp <= h/2 this is the standard piecewise quadratic of Bardenhagen & Kober (2004):
//   S(xi) = 1 - (xi^2 + lp^2) / (2 h lp)        |xi| < lp
//         = 1 - |xi| / h                        lp <= |xi| < h - lp
//         = (h + lp - |xi|)^2 / (4 h lp)        h - lp <= |xi| < h + lp
//         = 0                                   otherwise
//  dS/dx_p = -xi / (h lp), -sign(xi) / h, -sign(xi) (h + lp - |xi|) / (2 h lp), 0.
// It is evaluated here in an equivalent form that has no branches and no cancellation, and is
// valid for any lp (so also for the stretched domains below): with u = xi/h and a = lp/h, the
// hat's average is the hat plus the smoothing of its three kinks (slopes change by +1, -2, +1 at
// u = -1, 0, 1), each kink contributing E(t) = max(0, a - |t|)^2 / (4a):
//   S = hat(u) + E(u + 1) - 2 E(u) + E(u - 1),      hat(u) = max(0, 1 - |u|),
//   dS/dx_p = (hat(u + a) - hat(u - a)) / (2 lp).
// On the 3-node stencil (lp <= h/2, nearest node b, r = (x_p - x_b)/h) only E(r) survives:
//   S_b+1 = max(r, 0) + E(r),  S_b-1 = max(-r, 0) + E(r),  S_b = 1 - S_b-1 - S_b+1.
// The weights are C1 in x_p: the gradient is continuous across cell faces, which removes the
// cell-crossing noise of linear shape functions.
//
// lp_d is half the particle spacing of the particle's body (h_d / (2 particles_per_cell)), stored
// per particle in the field `gimp_half_width` at set-up. A node is non-zero only if
// |xi| < h + lp, so lp <= h/2 needs the 3 nodes per axis nearest the particle (3^D entries).
//
// domain_update: stretch (contiguous-GIMP-like; cf. cpGIMP in Uintah, Wallstedt & Guilkey 2008)
// sets lp_d = lp0_d F_dd every step from the deformation gradient F (requested from the scheme).
// Only the stretch along the axes is followed: shear and rotation of the domain are ignored (use
// cpdi for those). A stretched domain may reach lp = h, so the stencil is 4 nodes per axis
// (4^D entries); a longer domain is capped at lp = h (a warning reports how many), and
// F_dd <= 0 (an inverted domain) stops the run.
//
// Grid boundary: a domain that crosses the grid boundary would need the ghost node beyond it
// (node -1 or n+1). As in bspline2.cpp, the ghost is eliminated by extrapolating it linearly
// from its two inner neighbours, N_0 <- N_0 + 2 N_-1, N_1 <- N_1 - N_-1 (and N_n <- N_n + 2 N_n+1,
// N_n-1 <- N_n-1 - N_n+1); constants and linear functions take the values 1 = 2*1 - 1 and
// x_-1 = 2 x_0 - x_1 at the ghost, so partition of unity, sum grad N = 0 and linear reproduction
// hold at every position in the grid, up to and on its faces, in every axis. With lp <= h/2 the
// folded weights of a particle at t = (x_p - x_0)/h in [0, 1/2] are the linear hat,
// S_0 = 1 - t, S_1 = t (node 2 and beyond: 0); e.g. on the face S_0 = 1, so a particle on a
// held (fixed or slip) face has the face's normal velocity, and near it the normal velocity
// t v_1 vanishes with the distance t h, so with |v_1| dt < h (CFL) it cannot cross the face. The
// folded weights stay non-negative in the grid (N_1 >= N_-1 there, also for stretched domains).
// Dropping the ghost instead (zero weight, as before) left sum N = 1 - lp/(4h) on the face and sum
// grad N != 0: a particle on a held floor kept the velocity (lp/4h) v_1 of the row above the floor,
// moved down and left the grid. Stencil entries of ghost nodes carry the nearest valid node index
// and zero weight and gradient.
#include <spdlog/spdlog.h>

#include <array>
#include <cmath>

#include "framework/axis_stencil.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Gimp : public ShapeFunction<D> {
 public:
  static constexpr const char* name = "gimp";
  static constexpr const char* summary =
      "uniform GIMP (Bardenhagen & Kober 2004): hat functions averaged over a particle domain of "
      "half the particle spacing; 3^D nodes (4^D with domain stretch), C1 across cell faces";
  static Schema schema() {
    Schema s;
    s.choice("domain_update", {"none", "stretch"},
             "particle domain in time: none (uGIMP: fixed half-width lp0 = half the particle "
             "spacing of the body) or stretch (lp_d = lp0_d F_dd from the deformation gradient, "
             "contiguous-GIMP-like; 4^D nodes, lp capped at one cell with a warning, stops if "
             "F_dd <= 0)")
        .def("none");
    return s;
  }
  explicit Gimp(const Params& p) : stretch_(p.text("domain_update") == "stretch") {}

  int nodes_per_particle() const override { return ipow(stretch_ ? 4 : 3, D); }
  // A particle in cell row r reaches node rows r-1 .. r+2: its nearest node (r or r+1) +-1 with
  // 3 nodes per axis, nodes r-1 .. r+2 with 4.
  int rows_below() const override { return 1; }
  int rows_above() const override { return 2; }
  /// Node rows fixed by the particle's cell: the ghost layer is rows_below / rows_above wide.
  bool runs_on_ranks() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    const auto axes = Particles<D>::axis_names();
    half_width_ = sim.request_field(
        {"gimp_half_width", D, "m", "GIMP particle-domain half-width lp per axis", axes});
    if (stretch_) {
      half_width0_ = sim.request_field(
          {"gimp_half_width0", D, "m", "initial GIMP particle-domain half-width per axis", axes});
      deformation_gradient_ = sim.request_deformation_gradient();
    }
    // uGIMP (no stretch) needs lp <= h / 2: at least one particle per cell.
    for (const Body& body : sim.bodies)
      for (int d = 0; d < D && !stretch_; ++d)
        if (0.5 * body.spacing[size_t(d)] > 0.5 * sim.grid.cell[size_t(d)] * (1 + 1e-12)) {
          diag.error(sim.config.where("shape_function"), "shape_function",
                     "gimp: body '" + body.name +
                         "' has a particle spacing larger than the cell size; uGIMP needs at "
                         "least one particle per cell");
          return;
        }
    for (auto& set : sim.sets) initialize_particles(sim, set, 0, set.size());
  }

  /// lp = lp0 = spacing / 2 per axis.
  void initialize_particles(Simulation<D>& sim, ParticleSet<D>& set, size_t b, size_t e) override {
    Particles<D>& P = set.particles;
    for (int d = 0; d < D; ++d) {
      double* lp = P.col(half_width_, d);
      double* lp0 = stretch_ ? P.col(half_width0_, d) : nullptr;
      for (size_t i = b; i < e; ++i) {
        lp[i] = 0.5 * sim.bodies[P.body[i]].spacing[size_t(d)];
        if (lp0) lp0[i] = lp[i];
      }
    }
  }

  void begin_step(Simulation<D>& sim) override {
    if (!stretch_) return;
    for (auto& set : sim.sets)
      if (sim.failure.empty()) stretch_domains(sim, set.particles);
  }

  /// domain_update: stretch: lp = lp0 F_dd, capped at one cell.
  void stretch_domains(Simulation<D>& sim, Particles<D>& P) {
    const long n = long(P.size());
    long first_bad = n, first_capped = n, capped = 0;
    std::array<const double*, D> F{}, lp0{};
    std::array<double*, D> lp{};
    std::array<double, D> h{};
    for (int d = 0; d < D; ++d) {
      F[size_t(d)] = P.col(deformation_gradient_, d * D + d);
      lp0[size_t(d)] = P.col(half_width0_, d);
      lp[size_t(d)] = P.col(half_width_, d);
      h[size_t(d)] = sim.grid.cell[size_t(d)];
    }
#pragma omp parallel for schedule(static) num_threads(sim.threads) \
    reduction(min : first_bad, first_capped) reduction(+ : capped)
    for (long i = 0; i < n; ++i)
      for (size_t d = 0; d < size_t(D); ++d) {
        const double f = F[d][i];
        if (!(f > 0)) first_bad = std::min(first_bad, i);
        double l = lp0[d][i] * f;
        if (l > h[d]) {
          l = h[d];
          ++capped;
          first_capped = std::min(first_capped, i);
        }
        lp[d][i] = l;
      }
    if (first_bad < n) {
      const size_t i = size_t(first_bad);
      int d = 0;
      while (d + 1 < D && F[size_t(d)][i] > 0) ++d;
      sim.failure = "particle " + std::to_string(P.id[i]) + " (body " + sim.bodies[P.body[i]].name +
                    "): GIMP domain inverted, F_" + std::string(2, "xyz"[d]) + " = " +
                    format_number(F[size_t(d)][i]) +
                    " <= 0 (shape_function.domain_update: stretch)";
      return;
    }
    if (capped > 0 && !warned_) {
      warned_ = true;
      const size_t i = size_t(first_capped);
      spdlog::warn(
          "gimp: particle domains stretched beyond one cell are capped at lp = h: {} half-widths "
          "at step {} (first: particle {}, body {}); the stencil cannot follow a longer domain "
          "(warned once)",
          capped, sim.step, P.id[i], sim.bodies[P.body[i]].name);
    }
  }

  void evaluate(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                StencilBlock<D>& out) const override {
    if (stretch_)
      evaluate_m<4>(g, P, begin, count, out);
    else
      evaluate_m<3>(g, P, begin, count, out);
  }

 private:
  bool stretch_;
  bool warned_ = false;
  // max(v, 0) in arithmetic: exact, and unlike a select it is never sunk into a branch that
  // stops the loop from vectorising (also used for the boundary flags [b == 0] = max(1 - b, 0)
  // of integer-valued b).
  static double pos(double v) {
    return 0.5 * (v + std::fabs(v));
  }
  int half_width_ = -1, half_width0_ = -1, deformation_gradient_ = -1;

  /// M = 3: the nearest node and its neighbours; M = 4: nodes c-1 .. c+2 of cell c.
  template <int M>
  void evaluate_m(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                  StencilBlock<D>& out) const {
    out.count = count;
    AxisStencil<D, M> ax;
    for (int d = 0; d < D; ++d) {
      const double* x = P.col(P.position, d) + begin;
      const double* lp = P.col(half_width_, d) + begin;
      const double o = g.origin[size_t(d)], ih = g.inv_cell[size_t(d)];
      const int n = g.cells[d];  // last node index along d
      const double last = double(n);
      alignas(64) int32_t first[kBlock];
      // First stencil node, then the weights in branch-free double arithmetic (a loop of its
      // own, so that it vectorises), then the node indices.
      for (int p = 0; p < count; ++p) {
        const double xi = (x[p] - o) * ih;
        int c;
        if constexpr (M == 3) {
          c = int(xi + 0.5);  // nearest node
          c = c < 0 ? 0 : (c > n ? n : c);
        } else {
          c = int(xi);  // cell, inside the grid
          c = c < 0 ? 0 : (c > n - 1 ? n - 1 : c);
        }
        first[p] = c - 1;
      }
      if constexpr (M == 3) {
        // lp <= h/2, nearest node b, r = (x_p - x_b)/h in [-1/2, 1/2]: of the kink terms only
        // E(r) is non-zero, so S_b+1 = max(r, 0) + E(r), S_b-1 = max(-r, 0) + E(r) and
        // S_b = 1 - S_b-1 - S_b+1 (= 1 - |r| - 2 E(r)); the same for the gradients.
        // A block's particles usually share one half-width (uGIMP: half their body's spacing);
        // then the two divisions per particle and axis are done once for the block, with the
        // same operands, so the weights are the same bits.
        bool uniform = true;
        for (int p = 1; p < count; ++p) uniform &= lp[p] == lp[0];
        const double a0 = lp[0] * ih, gs0 = 0.5 / a0 * ih, q0 = 0.25 / a0;
        auto weights = [&](auto same_width) {
          for (int p = 0; p < count; ++p) {
            const double xi = (x[p] - o) * ih;
            const double b = double(first[p] + 1);
            const double r = xi - b;
            double a = a0, gs = gs0, q = q0;  // half-width in cells, gradient and kink factors
            if constexpr (!decltype(same_width)::value) {
              a = lp[p] * ih;
              gs = 0.5 / a * ih;
              q = 0.25 / a;
            }
            const double e = pos(a - std::fabs(r)), E = e * e * q;
            const double wp = pos(r) + E, wm = pos(-r) + E;
            const double gp = (pos(r + a) - pos(r - a)) * gs, gm = (pos(-r - a) - pos(a - r)) * gs;
            // Fold the ghost node b-1 = -1 (b == 0) or b+1 = n+1 (b == n) into its two inner
            // neighbours, as in bspline2.cpp: a field known on the grid is extrapolated linearly
            // to the ghost, u_-1 = 2 u_0 - u_1, so N_0 += 2 N_-1, N_1 -= N_-1 (and mirrored at n).
            // Constants and linear fields take exactly those ghost values, so partition of unity,
            // sum dN = 0 and linear reproduction hold up to and on the boundary; at the boundary
            // node the weights become the linear hat (S_0 = 1 - r, S_1 = r for 0 <= r < 1/2), so
            // a particle on a held face (r = 0) moves with it. lo = [b == 0], hi = [b == n].
            const double lo = pos(1.0 - b), hi = pos(b - (last - 1.0));
            const double wg = lo * wm + hi * wp, gg = lo * gm + hi * gp;  // the ghost's N, dN
            ax.w[d][0][p] = wm - wg;
            ax.w[d][1][p] = 1.0 - wp - wm + 2.0 * wg;
            ax.w[d][2][p] = wp - wg;
            ax.dw[d][0][p] = gm - gg;
            ax.dw[d][1][p] = -(gp + gm) + 2.0 * gg;
            ax.dw[d][2][p] = gp - gg;
          }
        };
        if (uniform)
          weights(std::true_type{});
        else
          weights(std::false_type{});
      } else {
        for (int p = 0; p < count; ++p) {
          const double xi = (x[p] - o) * ih;
          const double i0 = double(first[p]);
          const double a = lp[p] * ih;  // half-width in cells
          const double inv4a = 0.25 / a, grad_scale = 0.5 / a * ih;
          for (int j = 0; j < M; ++j) {
            const double i = i0 + j;
            const double u = xi - i;
            const double e0 = pos(a - std::fabs(u)), em = pos(a - std::fabs(u + 1.0)),
                         ep = pos(a - std::fabs(u - 1.0));
            const double s = pos(1.0 - std::fabs(u)) + (em * em - 2.0 * e0 * e0 + ep * ep) * inv4a;
            const double ds =
                (pos(1.0 - std::fabs(u + a)) - pos(1.0 - std::fabs(u - a))) * grad_scale;
            ax.w[d][j][p] = s;
            ax.dw[d][j][p] = ds;
          }
          // Only node c-1 = -1 (c == 0) and node c+2 = n+1 (c == n-1) can lie outside the grid
          // (a domain of lp <= h in cell c reaches no further). Fold each ghost into its two
          // inner neighbours by linear extrapolation, N_0 += 2 N_-1, N_1 -= N_-1 and
          // N_n += 2 N_n+1, N_n-1 -= N_n+1, exactly as in the 3-node branch above (both at once
          // for a one-cell grid). lo = [c == 0], hi = [c == n-1] (i0 = c - 1 is an integer).
          const double lo = pos(-i0), hi = pos(i0 + 3.0 - last);
          const double wl = lo * ax.w[d][0][p], wh = hi * ax.w[d][3][p];
          const double gl = lo * ax.dw[d][0][p], gh = hi * ax.dw[d][3][p];
          ax.w[d][0][p] -= wl;
          ax.w[d][1][p] += 2.0 * wl - wh;
          ax.w[d][2][p] += 2.0 * wh - wl;
          ax.w[d][3][p] -= wh;
          ax.dw[d][0][p] -= gl;
          ax.dw[d][1][p] += 2.0 * gl - gh;
          ax.dw[d][2][p] += 2.0 * gh - gl;
          ax.dw[d][3][p] -= gh;
        }
      }
      for (int p = 0; p < count; ++p) {
        const int i0 = first[p];
        for (int j = 0; j < M; ++j) {
          const int i = i0 + j;
          ax.set_node(g, d, j, p, i < 0 ? 0 : (i > n ? n : i));
        }
      }
      ax.offsets(g, d, x, count, out);
    }
    ax.tensor_product(count, out);
  }
};

LOAM_REGISTER(ShapeFunction, Gimp)

}  // namespace loam
