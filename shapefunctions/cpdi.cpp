// CPDI1: convected particle domain interpolation (Sadeghirad, Brannon & Burghardt 2011,
// Int. J. Numer. Meth. Engng 86:1435-1456, "A convected particle domain interpolation technique
// to extend applicability of the material point method for problems involving massive
// deformations", section 3).
//
// Each particle carries a parallelogram (2D) / parallelepiped (3D) / segment (1D) domain
//   x = x_p + R xi,  xi in [-1, 1]^D,   R = [r_1 ... r_D],   r_i = F r_i^0,
// with r_i^0 = half the particle spacing of the particle's body along axis i (the domains of the
// generated lattice tile the body) and F the deformation gradient that the scheme updates every
// step. The 2^D corners are x_alpha = x_p + sum_i s_alpha,i r_i with sign vector s_alpha in
// {-1, +1}^D. CPDI replaces the grid function N_I by its multilinear interpolation from the corner
// values inside the domain and averages over the domain (paper, section 3):
//
//   weight    S_I      = (1/V_p) int N_I dV         = 2^-D sum_alpha N_I(x_alpha)
//   gradient  grad S_I = (1/V_p) int grad N_I dV     = 2^-D R^-T sum_alpha s_alpha N_I(x_alpha)
//
// N_I is the linear (tent) function of grid node I. Derivation of the gradient in D dimensions:
// the domain map is affine, so grad_x M_alpha = R^-T grad_xi M_alpha for the corner functions
// M_alpha(xi) = prod_i (1 + s_alpha,i xi_i) / 2, and int_[-1,1]^D grad_xi M_alpha dxi = s_alpha;
// with dV = det R dxi and V_p = 2^D det R, (1/V_p) int grad M_alpha dV = 2^-D R^-T s_alpha.
// In 1D this is (N_I(x_p + r) - N_I(x_p - r)) / (2r). In 2D, with corners c1 = x_p - r1 - r2,
// c2 = x_p + r1 - r2, c3 = x_p + r1 + r2, c4 = x_p - r1 + r2 and V_p = 4 (r1 x r2), it expands to
// the paper's 2D gradient formula:
//   grad S_I = (1/V_p) [ (N_I(c1) - N_I(c3)) (r1_y - r2_y, r2_x - r1_x)
//                      + (N_I(c2) - N_I(c4)) (r1_y + r2_y, -r1_x - r2_x) ].
// Partition of unity, sum_I grad S_I = 0 and exact reproduction of linear fields
// (sum_I S_I x_I = x_p, sum_I x_I (x) grad S_I = R R^-1 = I) hold for any non-degenerate domain
// inside the grid, because they hold for the tent functions at every corner.
//
// Stencil: while every domain spans less than a cell along every axis (2 e_d < h_d, e_d the
// half-extent of the domain's bounding box), its corners lie in two adjacent cells per axis at
// most, and the corners' tent stencils are merged into the 3^D nodes b_d .. b_d + 2 from the
// lowest corner cell b_d: S_I and grad S_I summed per node in the evaluation, so the passes
// visit 3^D nodes instead of 4^D (2D: 9 instead of 16). Otherwise (a stretched domain) the
// stencil is the 2^D linear nodes of each corner's cell, entry k = alpha * 2^D + m, 4^D entries,
// with node indices repeated when corners share a cell (the scatter/gather add them up).
// begin_step() chooses between the two for the step (nodes_per_particle()).
// begin_step() turns F into R once per step (field `cpdi_domain`), checks every domain (inverted
// or degenerate, too stretched, corner outside the grid beyond an open face; corner_bounds) and
// measures the largest domain extent along the last axis for rows_below()/rows_above().
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Cpdi : public ShapeFunction<D> {
 public:
  static constexpr const char* name = "cpdi";
  static constexpr const char* summary =
      "CPDI1: linear functions averaged over particle domains convected with F (3^D nodes "
      "while domains span less than a cell, else 4^D)";
  static Schema schema() {
    Schema s;
    s.real("max_stretch", "-",
           "largest principal stretch of F (largest singular value) a particle domain may reach; "
           "beyond it the domain spans many cells, its corners no longer represent the tent "
           "functions inside it and the stencil reach grows, so the run stops with a message")
        .def("4")
        .above(1);
    s.real("min_jacobian", "-",
           "det F at or below which a domain counts as inverted or degenerate and the run stops")
        .def("1e-3")
        .above(0)
        .below(1);
    s.real("max_overhang", "-",
           "how far a domain corner may lie outside the grid beyond an open face (one that no "
           "boundary condition holds), as a fraction of the cell size, before the run stops "
           "(tent functions are extrapolated from the boundary cell, which keeps partition of "
           "unity and linear reproduction); at a held face the domain may overlap the face, "
           "only the particle stays inside")
        .def("0.1")
        .non_negative()
        .below(1);
    return s;
  }
  explicit Cpdi(const Params& p)
      : max_stretch_(p.real("max_stretch")),
        min_jacobian_(p.real("min_jacobian")),
        max_overhang_(p.real("max_overhang")) {}

  int nodes_per_particle() const override { return merged_ ? ipow(3, D) : 1 << (2 * D); }
  int max_nodes_per_particle() const override { return 1 << (2 * D); }
  int rows_below() const override { return reach_; }
  int rows_above() const override { return reach_ + 1; }
  /// Under mpirun the ghost layer is fixed when the grid is split (one row below, two above, as
  /// gimp's): every step checks that no domain has grown beyond it (check_ghost_layer).
  bool runs_on_ranks() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics&) override {
    F_ = sim.request_deformation_gradient();
    half_ = sim.request_field({"cpdi_half_spacing", D, "m",
                               "CPDI: initial domain half-size per axis, r_i^0 = spacing_i / 2",
                               Particles<D>::axis_names()});
    std::vector<std::string> names;
    for (int d = 0; d < D; ++d)
      for (int i = 0; i < D; ++i) names.push_back(std::string(1, "xyz"[d]) + "123"[i]);
    R_ = sim.request_field(
        {"cpdi_domain", D * D, "m",
         "CPDI domain vectors R = F diag(r^0): component d*D + i is coordinate d of r_i", names});
    for (auto& set : sim.sets) initialize_particles(sim, set, 0, set.size());
    std::string unused;
    update_domains(sim, unused);  // R and the reach before the first sort
  }

  /// r^0 = spacing / 2 per axis (the domain vectors R follow in begin_step).
  void initialize_particles(Simulation<D>& sim, ParticleSet<D>& set, size_t b, size_t e) override {
    auto& P = set.particles;
    for (size_t i = b; i < e; ++i)
      for (int d = 0; d < D; ++d)
        P.col(half_, d)[i] = 0.5 * sim.bodies[P.body[i]].spacing[size_t(d)];
  }

  void begin_step(Simulation<D>& sim) override {
    const int old_reach = reach_;
    update_domains(sim, sim.failure);
    if (sim.ranks->distributed()) check_ghost_layer(sim);
    // A larger reach may make the current slab colouring unsafe for this step's scatter.
    if (reach_ > old_reach && sim.failure.empty())
      for (auto& set : sim.sets)
        if (!set.partition.verify(set.particles, sim.grid, rows_below(), rows_above()))
          sim.sort(set);
  }

  void evaluate(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                StencilBlock<D>& out) const override {
    if (merged_)
      evaluate_merged(g, P, begin, count, out);
    else
      evaluate_corners(g, P, begin, count, out);
  }

 private:
  static constexpr int kCorners = 1 << D;

  /// What both evaluations need of each corner alpha of the block's domains, per axis d: the
  /// corner's cell (clamped into the grid: outside it, the boundary cell's tents extrapolate),
  /// its position t = xi - cell in that cell, and its gradient factor G = sum_i s_alpha,i A_di
  /// with A = 2^-D R^-T (the corner's grad S_I contribution is G N_I(x_alpha)).
  struct BlockCorners {
    alignas(64) int32_t cell[kCorners][D][kBlock];
    alignas(64) double t[kCorners][D][kBlock];
    alignas(64) double G[kCorners][D][kBlock];
  };

  void corners_of_block(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                        BlockCorners& out) const {
    const double* x[D];
    const double* r[D * D];
    for (int d = 0; d < D; ++d) x[d] = P.col(P.position, d) + begin;
    for (int c = 0; c < D * D; ++c) r[c] = P.col(R_, c) + begin;
    alignas(64) double A[D * D][kBlock];
    for (int p = 0; p < count; ++p) {
      double m[D][D], a[D][D];
      for (int d = 0; d < D; ++d)
        for (int i = 0; i < D; ++i) m[d][i] = r[d * D + i][p];
      inverse_transpose(m, a, 1.0 / kCorners);
      for (int d = 0; d < D; ++d)
        for (int i = 0; i < D; ++i) A[d * D + i][p] = a[d][i];
    }
    for (int alpha = 0; alpha < kCorners; ++alpha) {
      double s[D];  // the corner's sign vector, hoisted so that the loops vectorise
      for (int i = 0; i < D; ++i) s[i] = (alpha >> i) & 1 ? 1.0 : -1.0;
      for (int d = 0; d < D; ++d) {
        const double o = g.origin[size_t(d)], ih = g.inv_cell[size_t(d)];
        const int last = g.cells[d] - 1;
        double* __restrict G = out.G[alpha][d];
        alignas(64) double xc[kBlock];  // x_p + sum_i s_i r_di
        for (int p = 0; p < count; ++p) {
          double xv = x[d][p], gv = 0.0;
          for (int i = 0; i < D; ++i) {
            xv += s[i] * r[d * D + i][p];
            gv += s[i] * A[d * D + i][p];
          }
          xc[p] = xv;
          G[p] = gv;
        }
        for (int p = 0; p < count; ++p) {
          const double xi = (xc[p] - o) * ih;
          int c = int(xi);  // truncation: negative values are clamped to 0 below anyway
          c = c < 0 ? 0 : (c > last ? last : c);  // outside: extrapolate the boundary cell
          out.cell[alpha][d][p] = c;
          out.t[alpha][d][p] = xi - c;
        }
      }
    }
  }

  /// Domains under a cell: the corners' tents merged into 3^D nodes per particle.
  void evaluate_merged(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                       StencilBlock<D>& out) const {
    constexpr int C = kCorners, K = ipow(3, D);
    out.count = count;
    BlockCorners cs;
    corners_of_block(g, P, begin, count, cs);
    // Per axis: the lowest corner cell b (the first of the 3 nodes), and each corner's weights
    // on those 3 nodes: with o = cell - b in {0, 1}, (1 - o) N0, (1 - o) N1 + o N0, o N1
    // (exact: o is 0 or 1).
    alignas(64) double e[C][D][3][kBlock];
    alignas(64) int32_t node[D][3][kBlock];
    for (int d = 0; d < D; ++d) {
      const int n = g.cells[d];
      const int32_t stride = int32_t(g.node_stride[d]), lo = g.node_lo[size_t(d)];
      alignas(64) int32_t base[kBlock];
      for (int p = 0; p < count; ++p) {
        int b = cs.cell[0][d][p];
        for (int alpha = 1; alpha < C; ++alpha) b = std::min(b, cs.cell[alpha][d][p]);
        base[p] = b;
      }
      for (int alpha = 0; alpha < C; ++alpha)
        for (int p = 0; p < count; ++p) {
          const double off = double(cs.cell[alpha][d][p] - base[p]), n1 = cs.t[alpha][d][p],
                       n0 = 1.0 - n1;
          e[alpha][d][0][p] = (1.0 - off) * n0;
          e[alpha][d][1][p] = (1.0 - off) * n1 + off * n0;
          e[alpha][d][2][p] = off * n1;
        }
      for (int j = 0; j < 3; ++j)
        for (int p = 0; p < count; ++p) {
          const int i = base[p] + j;  // node n + 1 (all corners in the last cell) has weight 0
          node[d][j][p] = ((i > n ? n : i) - lo) * stride;  // the stored box's index (Grid)
        }
    }
    for (int k = 0; k < K; ++k) {
      int jd[D];
      for (int d = 0, q = k; d < D; ++d, q /= 3) jd[d] = q % 3;
      int32_t* __restrict node_k = out.node.data() + size_t(k) * kBlock;
      double* __restrict w_k = out.w.data() + size_t(k) * kBlock;
      double* __restrict grad_k = out.grad.data() + size_t(k) * D * kBlock;
      for (int p = 0; p < count; ++p) {
        int32_t nk = 0;
        for (int d = 0; d < D; ++d) nk += node[d][jd[d]][p];
        double w = 0, gr[D] = {};
        for (int alpha = 0; alpha < C; ++alpha) {
          double np = 1.0;  // N_I(x_alpha) of this node
          for (int d = 0; d < D; ++d) np *= e[alpha][d][jd[d]][p];
          w += np;
          for (int d = 0; d < D; ++d) gr[d] += cs.G[alpha][d][p] * np;
        }
        node_k[p] = nk;
        w_k[p] = w * (1.0 / C);
        for (int d = 0; d < D; ++d) grad_k[size_t(d) * kBlock + size_t(p)] = gr[d];
      }
    }
  }

  /// Any domain: the 2^D linear nodes of each corner's cell, 4^D entries, corner by corner
  /// (the per-axis tent weights of the corner's cell as in linear.cpp).
  void evaluate_corners(const Grid<D>& g, const Particles<D>& P, size_t begin, int count,
                        StencilBlock<D>& out) const {
    constexpr int C = kCorners;  // corners, and linear nodes per corner
    out.count = count;
    BlockCorners cs;
    corners_of_block(g, P, begin, count, cs);
    for (int alpha = 0; alpha < C; ++alpha) {
      alignas(64) int32_t base[kBlock];
      for (int p = 0; p < count; ++p) base[p] = 0;
      for (int d = 0; d < D; ++d) {
        const int32_t stride = int32_t(g.node_stride[d]), lo = g.node_lo[size_t(d)];
        for (int p = 0; p < count; ++p) base[p] += (cs.cell[alpha][d][p] - lo) * stride;
      }
      for (int m = 0; m < C; ++m) {
        const int k = alpha * C + m;
        int32_t offset = 0;
        for (int d = 0; d < D; ++d) offset += (m >> d) & 1 ? int32_t(g.node_stride[d]) : 0;
        int32_t* node = out.node.data() + size_t(k) * kBlock;
        double* w = out.w.data() + size_t(k) * kBlock;
        alignas(64) double N[kBlock];
        for (int p = 0; p < count; ++p) {
          node[p] = base[p] + offset;
          double np = 1.0;
          for (int d = 0; d < D; ++d) {
            const double t = cs.t[alpha][d][p];
            np *= (m >> d) & 1 ? t : 1.0 - t;
          }
          N[p] = np;
          w[p] = np * (1.0 / C);
        }
        for (int d = 0; d < D; ++d) {
          double* gr = out.grad.data() + (size_t(k) * D + size_t(d)) * kBlock;
          const double* G = cs.G[alpha][d];
          for (int p = 0; p < count; ++p) gr[p] = G[p] * N[p];
        }
      }
    }
  }

  double max_stretch_, min_jacobian_, max_overhang_;
  bool merged_ = false;  // this step: every domain under a cell along every axis (3^D nodes)
  int F_ = -1, half_ = -1, R_ = -1;
  int reach_ = 1;
  double max_cells_ = 0;  // the step's largest domain half-extent in cells, along any axis

  /// Under mpirun: a corner within e_d of its particle lies at most floor(e_d / h_d) + 1 cell
  /// rows from the particle's, and its tents reach one row further up; the ghost layer the
  /// ranks exchange (one row below, two above: the reach when the grid was split) holds that
  /// while every domain's half-extent is below a cell. The largest over the ranks decides, so
  /// that every rank stops at the same step with the same words.
  void check_ghost_layer(Simulation<D>& sim) const {
    const double cells = sim.ranks->max(max_cells_);
    if (int(std::floor(cells)) + 1 <= 1 || !sim.failure.empty()) return;
    sim.failure = "a CPDI particle domain reaches " + format_number(cells) +
                  " cells from its particle: under mpirun the ranks exchange a ghost layer of "
                  "one cell (the domains must stay within a cell of their particle; "
                  "docs/parallel.md); a smaller cpdi max_stretch, or a serial run";
  }
  static constexpr size_t kParallelMin =
      4096;  // fewer particles: not worth a fork/join  // rows a corner's cell can lie from the
             // particle's cell along the last axis

  static double det(const double (&m)[D][D]) {
    if constexpr (D == 1) {
      return m[0][0];
    } else if constexpr (D == 2) {
      return m[0][0] * m[1][1] - m[0][1] * m[1][0];
    } else {
      return m[0][0] * (m[1][1] * m[2][2] - m[1][2] * m[2][1]) -
             m[0][1] * (m[1][0] * m[2][2] - m[1][2] * m[2][0]) +
             m[0][2] * (m[1][0] * m[2][1] - m[1][1] * m[2][0]);
    }
  }

  /// a = scale * m^-T = scale * cof(m) / det(m).
  static void inverse_transpose(const double (&m)[D][D], double (&a)[D][D], double scale) {
    const double f = scale / det(m);
    if constexpr (D == 1) {
      a[0][0] = f;
    } else if constexpr (D == 2) {
      a[0][0] = f * m[1][1], a[0][1] = -f * m[1][0];
      a[1][0] = -f * m[0][1], a[1][1] = f * m[0][0];
    } else {
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
          a[i][j] = f * (m[i1][j1] * m[i2][j2] - m[i1][j2] * m[i2][j1]);
        }
    }
  }

  /// Largest singular value of F (exact; only called when |F|_Frobenius exceeds max_stretch).
  static double largest_stretch(const double (&f)[D][D]) {
    double c[D][D] = {};  // C = F^T F
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j)
        for (int k = 0; k < D; ++k) c[i][j] += f[k][i] * f[k][j];
    if constexpr (D == 1) {
      return std::sqrt(c[0][0]);
    } else if constexpr (D == 2) {
      const double h = 0.5 * (c[0][0] + c[1][1]), q = 0.5 * (c[0][0] - c[1][1]);
      return std::sqrt(h + std::sqrt(q * q + c[0][1] * c[0][1]));
    } else {
      // Largest eigenvalue of the symmetric C, trigonometric form (Smith 1961).
      const double p1 = c[0][1] * c[0][1] + c[0][2] * c[0][2] + c[1][2] * c[1][2];
      const double q = (c[0][0] + c[1][1] + c[2][2]) / 3.0;
      const double p2 = (c[0][0] - q) * (c[0][0] - q) + (c[1][1] - q) * (c[1][1] - q) +
                        (c[2][2] - q) * (c[2][2] - q) + 2.0 * p1;
      const double p = std::sqrt(p2 / 6.0);
      if (p == 0.0) return std::sqrt(q);
      double b[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) b[i][j] = (c[i][j] - (i == j ? q : 0.0)) / p;
      const double hr = std::clamp(0.5 * det(b), -1.0, 1.0);
      return std::sqrt(q + 2.0 * p * std::cos(std::acos(hr) / 3.0));
    }
  }

  /// R = F diag(r^0) for every particle of every set, the checks, and the reach. Writes a
  /// message naming the first bad particle into `failure` (left untouched when all domains are
  /// fine).
  void update_domains(Simulation<D>& sim, std::string& failure) {
    double max_extent = 0;  // along the last axis
    double max_cells = 0;   // largest half-extent in cells along any axis
    for (auto& set : sim.sets)
      if (failure.empty()) update_domains(sim, set.particles, failure, max_extent, max_cells);
    max_cells_ = max_cells;
    // Merge below a spread of 2 e < h, with a margin so that rounding in the corner coordinates
    // cannot put two corners two cells apart.
    merged_ = 2.0 * max_cells < 1.0 - 1e-9;
    // Rows: a corner lies within max_extent of the particle along the last axis, so its cell row
    // differs from the particle's by at most floor(max_extent / h) + 1 (one more than ceil when
    // the ratio is an integer, against round-off); its tent functions reach one row further up.
    reach_ = int(std::floor(max_extent * sim.grid.inv_cell[D - 1])) + 1;
  }

  void update_domains(Simulation<D>& sim, Particles<D>& P, std::string& failure,
                      double& largest_extent, double& largest_cells) {
    double max_extent = largest_extent, max_cells = largest_cells;
    const auto inv_cell = sim.grid.inv_cell;
    const size_t n = P.size();
    const double* Fc[D * D];
    double* Rc[D * D];
    const double *h0[D], *x[D];
    for (int c = 0; c < D * D; ++c) Fc[c] = P.col(F_, c), Rc[c] = P.col(R_, c);
    for (int d = 0; d < D; ++d) h0[d] = P.col(half_, d), x[d] = P.col(P.position, d);
    double lo[D], hi[D];
    for (int d = 0; d < D; ++d) corner_bounds(sim, d, lo[d], hi[d]);
    const double s2 = max_stretch_ * max_stretch_, jmin = min_jacobian_;
    size_t suspect = n;  // first particle failing a cheap (sufficient) test
#pragma omp parallel for schedule(static) num_threads(sim.threads) if (n >= kParallelMin) \
    reduction(max                                                                         \
              : max_extent, max_cells) reduction(min                                      \
                                                 : suspect)
    for (size_t i = 0; i < n; ++i) {
      double f[D][D], frob2 = 0;
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) {
          f[d][j] = Fc[d * D + j][i];
          frob2 += f[d][j] * f[d][j];
          Rc[d * D + j][i] = f[d][j] * h0[j][i];
        }
      bool ok = det(f) > jmin && frob2 <= s2;  // sigma_max(F) <= |F|_Frobenius
      for (int d = 0; d < D; ++d) {
        double e = 0;  // half-extent of the domain's bounding box along d
        for (int j = 0; j < D; ++j) e += std::fabs(f[d][j] * h0[j][i]);
        ok = ok && x[d][i] - e >= lo[d] && x[d][i] + e <= hi[d];
        if (d == D - 1) max_extent = std::max(max_extent, e);
        max_cells = std::max(max_cells, e * inv_cell[size_t(d)]);
      }
      if (!ok) suspect = std::min(suspect, i);
    }
    largest_extent = max_extent;
    largest_cells = max_cells;
    if (suspect == n) return;
    // Exact checks from the first suspect on (the Frobenius test is only sufficient).
    size_t bad = n;
#pragma omp parallel for schedule(static)                                   \
    num_threads(sim.threads) if (n - suspect >= kParallelMin) reduction(min \
                                                                        : bad)
    for (size_t i = suspect; i < n; ++i) {
      int axis = 0;
      if (check(sim, P, i, axis) != Problem::kNone) bad = std::min(bad, i);
    }
    if (bad < n) failure = message(sim, P, bad);
  }

  static std::string num(double v) {  // 6 significant digits are enough for a message
    char b[32];
    std::snprintf(b, sizeof b, "%.6g", v);
    return b;
  }

  enum class Problem { kNone, kInverted, kStretched, kOutside };

  /// Where the domain corners may reach along d: max_overhang of a cell beyond an open face, as
  /// far as the domain goes at a held face (Simulation::held_faces). There the particle itself
  /// stays inside and only its domain overlaps the face, as a GIMP domain does: the corners
  /// outside take the boundary cell's tents extrapolated, the same linear extrapolation as
  /// GIMP's ghost-node fold. A domain resting on a held face dips a corner through it as soon
  /// as it rotates (a water column running into the corner of a tank: overhang 0.1 cell after
  /// 212 steps), which is no sign of material leaving the grid. The corners are not pulled back
  /// inside: R = F diag(r^0), so that would change F, and with it the domain volume 2^D det R
  /// against the particle volume.
  void corner_bounds(const Simulation<D>& sim, int d, double& lo, double& hi) const {
    const double inf = std::numeric_limits<double>::infinity();
    const double slack = max_overhang_ * sim.grid.cell[size_t(d)];
    lo = sim.held_faces.lower[size_t(d)] > -inf ? -inf : sim.grid.origin[size_t(d)] - slack;
    hi = sim.held_faces.upper[size_t(d)] < inf ? inf : sim.grid.upper(d) + slack;
  }

  /// Exact check of particle i's domain; `axis` is set for kOutside.
  Problem check(const Simulation<D>& sim, const Particles<D>& P, size_t i, int& axis) const {
    double f[D][D];
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j) f[d][j] = P.col(F_, d * D + j)[i];
    if (!(det(f) > min_jacobian_)) return Problem::kInverted;
    if (!(largest_stretch(f) <= max_stretch_)) return Problem::kStretched;
    for (int d = 0; d < D; ++d) {
      double e = 0;
      for (int j = 0; j < D; ++j) e += std::fabs(f[d][j] * P.col(half_, j)[i]);
      const double xp = P.col(P.position, d)[i];
      double lo, hi;
      corner_bounds(sim, d, lo, hi);
      if (xp - e < lo || xp + e > hi) {
        axis = d;
        return Problem::kOutside;
      }
    }
    return Problem::kNone;
  }

  /// The message for a particle whose check failed.
  std::string message(const Simulation<D>& sim, const Particles<D>& P, size_t i) const {
    const auto& g = sim.grid;
    int d = 0;
    const Problem what = check(sim, P, i, d);
    double f[D][D];
    for (int a = 0; a < D; ++a)
      for (int j = 0; j < D; ++j) f[a][j] = P.col(F_, a * D + j)[i];
    std::ostringstream s;
    s << "particle " << P.id[i] << " of body '" << sim.bodies[P.body[i]].name << "' at (";
    for (int a = 0; a < D; ++a) s << (a ? ", " : "") << num(P.col(P.position, a)[i]);
    s << "): ";
    const char* other =
        "a shape function without deforming particle domains (e.g. linear or bspline2)";
    if (what == Problem::kInverted) {
      s << "CPDI domain inverted or degenerate (det F = " << num(det(f))
        << " <= min_jacobian = " << num(min_jacobian_)
        << "); remedy: a smaller time step (time.cfl), a finer grid, or " << other;
    } else if (what == Problem::kStretched) {
      s << "CPDI domain too distorted (largest principal stretch of F " << num(largest_stretch(f))
        << " > max_stretch = " << num(max_stretch_)
        << "); remedy: a smaller time step (time.cfl) if the deformation is spurious, a larger "
           "shape_function.max_stretch (less accurate: CPDI1 samples the tent functions only at "
           "the corners of a domain that then spans more cells), or "
        << other;
    } else {
      double e = 0;
      for (int j = 0; j < D; ++j) e += std::fabs(f[d][j] * P.col(half_, j)[i]);
      const double xp = P.col(P.position, d)[i];
      s << "CPDI domain corner leaves the grid along "
        << "xyz"[d] << " (domain spans " << num(xp - e) << " to " << num(xp + e) << " m, grid "
        << num(g.origin[size_t(d)]) << " to " << num(g.upper(d)) << " m, allowed overhang "
        << num(max_overhang_ * g.cell[size_t(d)])
        << " m); remedy: extend the grid (grid.origin, grid.extent) beyond the material, a "
           "smaller time step (time.cfl), or "
        << other;
    }
    return s.str();
  }
};

LOAM_REGISTER(ShapeFunction, Cpdi)

}  // namespace loam
