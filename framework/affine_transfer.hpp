#pragma once
// The affine particle-in-cell transfer (APIC, Jiang, Schroeder, Selle, Teran & Stomakhin 2015,
// J. Comput. Phys. 280 / SIGGRAPH 2015), as a building block every scheme's P2G and G2P loops
// call per particle and stencil entry, for each velocity field it transfers (the single-phase
// velocity; the solid and water velocities of the two-phase schemes).
//
// Each particle carries, per field, the velocity's first moment about it, B_p (a D x D field).
// G2P from the updated grid velocities v_I, at the particle's position before the move:
//   v_p = sum_I N_Ip v_I,   B_p = sum_I N_Ip v_I (x_I - x_p)^T;
// P2G (and a MUSL re-map), with the inertia D_p = sum_I N_Ip (x_I - x_p)(x_I - x_p)^T of the
// particle's current position:
//   (m v)_I = sum_p m_p N_Ip (v_p + B_p D_p^-1 (x_I - x_p)).
// D_p comes from the weights: for tensor-product weights (gimp, bspline2) the shape function
// gives x_I - x_p and D_p = diag(sum_j w_j dx_j^2) per axis from its axis values
// (axis_stencil.hpp; h^2/4 per axis for interior quadratic B-splines), vectorised over the
// block; for CPDI (and the offsets of linear tents) they come from the node coordinates, with
// D_p's sum and inverse per particle (invertible: a domain spans nodes). On a tensor-product
// stencil (M nodes per axis, entry k at axis node i_e(k) along axis e) the offsets are kept per
// axis and the per-entry affine algebra factors over the axes: the P2G's m C (x_I - x_p) is
// sum_e mC_:e dx_e(i_e), a sum of D per-axis terms formed once per particle (Momenta), and the
// G2P's B_de = sum_k w_k v_k,d dx_e(i_e(k)) = sum_i dx_e(i) S_e(i)_d, where S_e(i) sums w_k v_k
// over the entries at axis node i (MomentSum): additions per entry instead of D^2 products. Keeping
// B_p, not C_p = B_p D_p^-1, and taking D_p where the particle is when it scatters is what
// conserves angular momentum over the move for weights whose D_p changes with position. Linear and
// angular momentum are conserved by the transfers; the affine part carries no PIC dissipation and
// no FLIP noise (tests/test_apic.cpp).
//
// Multilinear tents (shape functions whose stencil does not cover the particle's domain) are the
// exception: there N_Ip D_p^-1 (x_I - x_p) = grad N_Ip (Jiang et al. 2015, section 5.3) does not
// vanish with N_Ip, so a node a particle has just reached carries the affine term on a vanishing
// mass and an acceleration f_I / m_I that grows as 1 / N_Ip. Measured on a bar
// translating across 0.1 m cells and a spinning disk (tests/test_apic.cpp): B_p D_p^-1 with D_p at
// the new position, and C_p = sum_I v_I grad N_Ip^T from the updated grid, blew up at the bar's
// free-end cell crossings (t = 0.25 s, 0.43 s); C_p = the velocity gradient of MUSL's plain
// re-map damps the disk's rotation away at its free surface (0.2 % per step), and with an affine
// re-map it blows up. What works: USF, where the particle carries C_p = the velocity gradient of
// the P2G field (affine part included) at the particle, the gradient the stress update takes; its
// light nodes hold their points' own affine velocities. So with linear tents the field holds C_p
// (`gradient_form()`), the scheme stores it from its USF gradient pass, and schemes without USF
// refuse the combination; angular momentum is then kept only approximately (the tests print it).
//
// The Taylor particle-in-cell transfer (TPIC; Nakamura, Matsumura & Mizutani 2023, Comput.
// Methods Appl. Mech. Engrg. 403, 115720) is the same P2G with the particle's velocity gradient
// C_p in place of B_p D_p^-1, the first-order Taylor expansion of the particle's velocity field:
//   G2P: v_p = sum_I N_Ip v_I,   C_p = sum_I v_I grad N_Ip^T,
//   P2G: (m v)_I = sum_p m_p N_Ip (v_p + C_p (x_I - x_p)).
// No inertia D_p and no inverse. For multilinear tents N_Ip D_p^-1 (x_I - x_p) = grad N_Ip, so
// APIC already is TPIC there (and takes it from the USF pass, above). For the other shape
// functions C_p D_p differs from B_p (interior quadratic B-splines, a particle h/4 from its
// nearest node: for the node 1.25 h away grad N = -0.25/h, N D_p^-1 (x_I - x_p) = -0.156/h), so
// TPIC conserves angular momentum only approximately; tests/test_apic.cpp prints its drift beside
// APIC's. Fu, Guo, Gast, Jiang & Teran (2017, "A polynomial particle-in-cell method", ACM TOG 36)
// is also cited for higher-order affine transfers: that is PolyPIC, which adds polynomial modes
// beyond the affine one to APIC; it is not built here.
#include <Eigen/Dense>
#include <string>
#include <type_traits>
#include <vector>

#include "force_inline.hpp"
#include "particles.hpp"
#include "shape_function.hpp"

namespace loam {

/// How a pass's loop runs the per-particle affine algebra, compiled per block
/// (AffineTransfer::with_form): kOff, no affine transfer; kAny, the form decided per particle
/// (CPDI, node coordinates, TPIC, linear tents); kProduct, APIC's B_p on a tensor-product stencil
/// of axis_nodes_of(NPP) nodes per axis, the product form with no check per stencil entry.
enum class AffineForm { kOff, kAny, kProduct };

/// A pass's loop over a particle's stencil entries, entry(k) for k < npp: unrolled with an
/// affine form (the product form's axis indices of entry k are then constants; a plain loop
/// sharing the pragma made FLIP's P2G 4 % slower), plain without one.
template <AffineForm FORM, class Entry>
LOAM_FORCE_INLINE void for_each_entry(int npp, Entry&& entry) {
  if constexpr (FORM != AffineForm::kOff) {
#pragma GCC unroll 16
    for (int k = 0; k < npp; ++k) entry(k);
  } else {
    for (int k = 0; k < npp; ++k) entry(k);
  }
}

template <int D>
class AffineTransfer {
 public:
  /// Entries of a stencil handled per particle (CPDI's widest, 4^D).
  static constexpr int kMaxEntries = ipow(4, D);

  /// x_I - x_p of every stencil entry of a particle, and D_p^-1 (APIC's B_p form only).
  struct Stencil {
    /// x_I - x_p of entry k along axis j: per axis in the stencil block (its layout, no copy;
    /// m nodes per axis, entry k is axis node (k / m^j) % m along j) or per entry in `own`
    /// (m = 0, computed from the node coordinates).
    LOAM_FORCE_INLINE double dx(int k, int j) const {
      if (m == 0) return at[(size_t(k) * D + size_t(j)) * stride];
      for (int e = 0; e < j; ++e) k /= m;
      return axis(j, k % m);
    }
    /// The offset of axis node i along axis j (m > 0: the block's layout, stride kBlock).
    LOAM_FORCE_INLINE double axis(int j, int i) const {
      return at[(size_t(j) * size_t(m) + size_t(i)) * kBlock];
    }
    template <int M>
    LOAM_FORCE_INLINE double axis(int j, int i) const {
      return at[(size_t(j) * M + size_t(i)) * kBlock];
    }
    const double* at = own;
    size_t stride = 1;
    int m = 0;                         // nodes per axis of a tensor-product stencil, else 0
    double own[kMaxEntries * D] = {};  // value-initialised: declared once per block
    double inertia_inv[D][D] = {};
  };

  /// Nodes per axis of a tensor-product stencil of NPP entries (NPP = M^D), 0 if none: the
  /// product form of the affine sums below is compiled for it.
  static constexpr int axis_nodes_of(int npp) {
    for (int m = 2; m <= 4; ++m)
      if (ipow(m, D) == npp) return m;
    return 0;
  }

  /// One particle's sum for APIC's B_p (or TPIC's C_p) over its stencil entries, while the
  /// G2P gathers them (add_moment, then moment). On a tensor-product stencil B_p's sum
  /// factors: B_de = sum_k w_k v_k,d dx_e(k) = sum_i dx_e(i) S_e(i)_d, where S_e(i) sums w_k v_k
  /// over the entries at axis node i along e, so an entry costs D^2 additions instead of D^2
  /// products and additions.
  /// Cleared per particle (clear) by the pass that sums it, so that a FLIP pass declaring
  /// one pays nothing. F = kProduct: the product form only (with_form).
  template <int NPP, AffineForm F = AffineForm::kAny>
  struct MomentSum {
    static constexpr int M = axis_nodes_of(NPP);
    static constexpr bool kProduct = F == AffineForm::kProduct;
    static_assert(!kProduct || M > 0, "the product form needs a tensor-product stencil");
    double axis[D][M > 0 ? M : 1][D];  // S_e(i): the product form
    double B[D][D];                    // per entry: CPDI, node coordinates, TPIC
    LOAM_FORCE_INLINE void clear() {
      for (int e = 0; e < D; ++e)
        for (int i = 0; i < (M > 0 ? M : 1); ++i)
          for (int d = 0; d < D; ++d) axis[e][i][d] = 0.0;
      if constexpr (!kProduct)
        for (int d = 0; d < D; ++d)
          for (int j = 0; j < D; ++j) B[d][j] = 0.0;
    }
  };

  /// The transfer's name in a scheme's `transfer` key: apic or tpic.
  static bool is_affine(const std::string& transfer) {
    return transfer == "apic" || transfer == "tpic";
  }

  /// Whether a block's stencil (after evaluate) takes the product form of APIC's B_p: a
  /// tensor-product stencil of axis_nodes_of(NPP) nodes per axis with its offsets, B_p not C_p.
  template <int NPP>
  bool product_form(const StencilBlock<D>& st) const {
    constexpr int M = axis_nodes_of(NPP);
    return M > 0 && st.has_affine && st.axis_nodes == M && !gradient_form_;
  }
  /// Calls fn(std::integral_constant<AffineForm, F>) with the block's form (product_form:
  /// kProduct, else kAny), so that a scheme's APIC loop is compiled without the per-entry checks
  /// of the general form.
  template <int NPP, class Fn>
  LOAM_FORCE_INLINE void with_form(const StencilBlock<D>& st, Fn&& fn) const {
    if constexpr (axis_nodes_of(NPP) > 0)
      if (product_form<NPP>(st))
        return fn(std::integral_constant<AffineForm, AffineForm::kProduct>{});
    fn(std::integral_constant<AffineForm, AffineForm::kAny>{});
  }

  /// Node coordinates (x_I - x_p without divisions) and the form: B_p (APIC), or C_p for TPIC
  /// (`taylor`) and for shape functions whose stencil does not cover the particle's domain
  /// (linear tents, either transfer: the header).
  void setup(const Grid<D>& grid, const ShapeFunction<D>& shape, bool taylor) {
    usf_gradient_ = !shape.stencil_covers_domain();
    gradient_form_ = taylor || usf_gradient_;
    node_x_.resize(grid.num_nodes * D);
    for (size_t n = 0; n < grid.num_nodes; ++n)
      for (int d = 0; d < D; ++d) node_x_[n * D + size_t(d)] = grid.node_coord(n, d);
  }
  /// Whether the particles carry C_p (TPIC, linear tents) rather than APIC's B_p.
  bool gradient_form() const { return gradient_form_; }
  /// Whether C_p is the velocity gradient of USF's P2G field, stored by the scheme's USF
  /// gradient pass (linear tents: the header), rather than taken at the G2P.
  bool needs_usf() const { return usf_gradient_; }
  /// The shape function's stencil fits (else: a located error by the scheme).
  static bool fits(const ShapeFunction<D>& shape) {
    return shape.max_nodes_per_particle() <= kMaxEntries;
  }

  /// The shape function's stencil of a block for a pass that transfers the affine velocity:
  /// it also asks for the offsets (and D_p^-1 for APIC's B_p form), which tensor-product shape
  /// functions give from their axis values (StencilBlock::affine).
  /// `on` false: the plain evaluation (a pass of a scheme run without an affine transfer).
  void evaluate(const Simulation<D>& sim, const Particles<D>& P, size_t begin, int count,
                StencilBlock<D>& st, bool on = true) const {
    if (on) st.affine = gradient_form_ ? StencilBlock<D>::kOffsets : StencilBlock<D>::kInertia;
    sim.shape->evaluate(sim.grid, P, begin, count, st);
    st.affine = StencilBlock<D>::kNone;  // the other passes' evaluations need none
  }

  /// A pass's block: evaluate its stencil (with the affine geometry when `on`) and call
  /// kernel(std::integral_constant<AffineForm, F>) with its form: kOff when not `on`, else as
  /// with_form. The schemes compile their loops per form this way.
  template <int NPP, class Kernel>
  LOAM_FORCE_INLINE void evaluate_with_form(const Simulation<D>& sim, const Particles<D>& P,
                                            size_t begin, int count, StencilBlock<D>& st, bool on,
                                            Kernel&& kernel) const {
    evaluate(sim, P, begin, count, st, on);
    if (!on) return kernel(std::integral_constant<AffineForm, AffineForm::kOff>{});
    with_form<NPP>(st, kernel);
  }

  /// x_I - x_p of every stencil entry of particle p of the block (index i in P) and D_p^-1:
  /// from the stencil block when its shape function gave them (AffineTransfer::evaluate), else
  /// from the node coordinates (stencil_from_nodes).
  LOAM_FORCE_INLINE void stencil(const Particles<D>& P, const StencilBlock<D>& st, int p, size_t i,
                                 int npp, Stencil& a) const {
    if (!st.has_affine) {
      stencil_from_nodes(P, st, p, i, npp, a);
      return;
    }
    a.at = st.dx.data() + p;
    a.stride = kBlock;
    a.m = st.axis_nodes;
    if (gradient_form_) return;
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j)
        a.inertia_inv[d][j] = d == j ? st.inertia_inv[size_t(d) * kBlock + size_t(p)] : 0.0;
  }

  /// The same from the node coordinates: D_p = sum_k N_k dx_k dx_k^T and its inverse (linear
  /// tents, CPDI).
  void stencil_from_nodes(const Particles<D>& P, const StencilBlock<D>& st, int p, size_t i,
                          int npp, Stencil& a) const {
    double xp[D];
    for (int d = 0; d < D; ++d) xp[d] = P.col(P.position, d)[i];
    a.at = a.own;
    a.stride = 1;
    a.m = 0;
    Eigen::Matrix<double, D, D> inertia = Eigen::Matrix<double, D, D>::Zero();
    for (int k = 0; k < npp; ++k) {
      const size_t kp = size_t(k) * kBlock + size_t(p);
      const double* xI = node_x_.data() + size_t(st.node[kp]) * D;
      double* dx = a.own + size_t(k) * D;
      for (int d = 0; d < D; ++d) dx[d] = xI[d] - xp[d];
      if (gradient_form_) continue;  // C_p needs no inertia
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) inertia(d, j) += st.w[kp] * dx[d] * dx[j];
    }
    if (gradient_form_) return;
    const Eigen::Matrix<double, D, D> inv = inertia.inverse();
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j) a.inertia_inv[d][j] = inv(d, j);
  }

  /// The D x D columns (row-major) of the particle field holding B_p (or C_p), looked up once
  /// per block: looked up per particle through Particles::col, a chain of dependent loads held
  /// up the P2G and G2P loops (bench/RESULTS.md, the APIC profile).
  struct Columns {
    double* c[D * D] = {};
    LOAM_FORCE_INLINE void load(size_t i, double (&B)[D][D]) const {
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) B[d][j] = c[d * D + j][i];
    }
    LOAM_FORCE_INLINE void store(size_t i, const double (&B)[D][D]) const {
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) c[d * D + j][i] = B[d][j];
    }
  };
  static Columns columns(Particles<D>& P, int field) {
    Columns c;
    for (int k = 0; k < D * D; ++k) c.c[k] = P.col(field, k);
    return c;
  }

  /// mC = m B D^-1 of particle i from its field's columns, at the stencil geometry `a`.
  LOAM_FORCE_INLINE void matrix(const Columns& field, size_t i, double m, const Stencil& a,
                                double (&mC)[D][D]) const {
    double B[D][D];
    field.load(i, B);
    matrix(m, B, a, mC);
  }

  /// mC = m_p B_p D_p^-1 (B row-major); m_p C_p in the gradient form.
  LOAM_FORCE_INLINE void matrix(double mp, const double (&B)[D][D], const Stencil& a,
                                double (&mC)[D][D]) const {
    if (gradient_form_) {
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) mC[d][j] = mp * B[d][j];
      return;
    }
    if (a.m > 0) {  // D_p diagonal (axis_stencil.hpp)
      for (int d = 0; d < D; ++d)
        for (int j = 0; j < D; ++j) mC[d][j] = mp * B[d][j] * a.inertia_inv[j][j];
      return;
    }
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j) {
        double c = 0;
        for (int e = 0; e < D; ++e) c += mp * B[d][e] * a.inertia_inv[e][j];
        mC[d][j] = c;
      }
  }

  /// The momentum per unit weight each stencil entry k of a particle sends to its node, a_k =
  /// m v_p + (m B D^-1)(x_I - x_p) (the scatter adds w_k a_k; momenta fills it). On a
  /// tensor-product stencil the affine part is a sum over the axes, a_k = sum_e t_e(i_e(k)) with
  /// t_0(i) = m v_p + mC_:0 dx_0(i) and t_e(i) = mC_:e dx_e(i): D (D - 1) additions per entry,
  /// done where the scatter reads it (unrolled, i_e(k) are constants); the same bits as the
  /// per-entry sum m v_p + mC_:0 dx_0 + mC_:1 dx_1 + ...
  /// F = kProduct: the product form only (with_form).
  template <int NPP, AffineForm F = AffineForm::kAny>
  struct Momenta {
    static constexpr int M = axis_nodes_of(NPP);
    static constexpr bool kProduct = F == AffineForm::kProduct;
    static_assert(!kProduct || M > 0, "the product form needs a tensor-product stencil");
    bool product = kProduct;
    double t[D][M > 0 ? M : 1][D] = {};  // the product form: t_e(i) (declare once per block)
    double a[kProduct ? 1 : NPP > 0 ? NPP : kMaxEntries][D] = {};  // per entry (CPDI, nodes)
    LOAM_FORCE_INLINE double at(int k, int d) const {
      if constexpr (M > 0) {
        if (kProduct || product) {
          double v = t[0][k % M][d];
          for (int e = 1, r = k / M; e < D; ++e, r /= M) v += t[e][r % M][d];
          return v;
        }
      }
      return a[k][d];
    }
  };
  template <int NPP, AffineForm F>
  LOAM_FORCE_INLINE static void momenta(const Stencil& s, int npp, const double (&mv)[D],
                                        const double (&mC)[D][D], Momenta<NPP, F>& out) {
    constexpr int M = Momenta<NPP, F>::M;
    if constexpr (M > 0) {
      if constexpr (!Momenta<NPP, F>::kProduct) out.product = s.m == M;
      if (Momenta<NPP, F>::kProduct || out.product) {
        for (int e = 0; e < D; ++e)
          for (int i = 0; i < M; ++i) {
            const double x = s.template axis<M>(e, i);
            for (int d = 0; d < D; ++d)
              out.t[e][i][d] = e == 0 ? mv[d] + mC[d][0] * x : mC[d][e] * x;
          }
        return;
      }
    }
    if constexpr (!Momenta<NPP, F>::kProduct)
      for (int k = 0; k < npp; ++k)
        for (int d = 0; d < D; ++d) {
          double v = mv[d];
          for (int j = 0; j < D; ++j) v += mC[d][j] * s.dx(k, j);
          out.a[k][d] = v;
        }
  }

  /// G2P of stencil entry k of block particle p, weight w, node velocity v_I: APIC's
  /// B += w v_I (x_I - x_p)^T (in the product form: MomentSum), TPIC's C += v_I grad N^T
  /// (nothing with linear tents, whose C_p the USF gradient pass stores).
  template <int NPP, AffineForm F>
  LOAM_FORCE_INLINE void add_moment(MomentSum<NPP, F>& sum, const StencilBlock<D>& st, int k, int p,
                                    double w, const double* vI, const Stencil& s) const {
    constexpr int M = MomentSum<NPP, F>::M;
    constexpr bool kProduct = MomentSum<NPP, F>::kProduct;  // with_form checked the block
    if constexpr (!kProduct) {
      if (usf_gradient_) return;
      if (gradient_form_) {
        for (int j = 0; j < D; ++j) {
          const double g = st.grad[(size_t(k) * D + size_t(j)) * kBlock + size_t(p)];
          for (int d = 0; d < D; ++d) sum.B[d][j] += vI[d] * g;
        }
        return;
      }
    }
    if constexpr (M > 0) {
      if (kProduct || s.m == M) {
        for (int e = 0, r = k; e < D; ++e, r /= M)
          for (int d = 0; d < D; ++d) sum.axis[e][r % M][d] += w * vI[d];
        return;
      }
    }
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j) sum.B[d][j] += w * vI[d] * s.dx(k, j);
  }

  /// The particle's B_p (or C_p) from its sum over the entries.
  template <int NPP, AffineForm F>
  LOAM_FORCE_INLINE void moment(const MomentSum<NPP, F>& sum, const Stencil& s,
                                double (&B)[D][D]) const {
    constexpr int M = MomentSum<NPP, F>::M;
    if constexpr (M > 0) {
      if (MomentSum<NPP, F>::kProduct || (!gradient_form_ && s.m == M)) {
        for (int d = 0; d < D; ++d)
          for (int e = 0; e < D; ++e) {
            double b = 0;
            for (int i = 0; i < M; ++i) b += sum.axis[e][i][d] * s.template axis<M>(e, i);
            B[d][e] = b;
          }
        return;
      }
    }
    for (int d = 0; d < D; ++d)
      for (int j = 0; j < D; ++j) B[d][j] = sum.B[d][j];
  }

  /// The particle field holding B_p (or C_p), requested only when APIC is on. `name` and
  /// `what` (e.g. "affine_moment", "velocity") name the transferred field.
  FieldInfo field_info(const std::string& name, const std::string& what) const {
    std::vector<std::string> names;
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) names.push_back(std::string(1, "xyz"[i]) + "xyz"[j]);
    if (usf_gradient_)
      return {name, D * D, "1/s",
              "APIC or TPIC with linear tents (update: usf): C_p, the gradient of the P2G " + what +
                  " field at the particle; the particle's field is v_p + C_p (x - x_p)",
              names};
    if (gradient_form_)
      return {name, D * D, "1/s",
              "TPIC's C_p = sum_I v_I grad N_Ip^T of the " + what +
                  " (Nakamura et al. 2023): the particle's field is v_p + C_p (x - x_p)",
              names};
    return {name, D * D, "m^2/s",
            "APIC's B_p = sum_I N_Ip v_I (x_I - x_p)^T of the " + what +
                " (Jiang et al. 2015): with the inertia D_p the particle's field is v_p + B_p "
                "D_p^-1 (x - x_p)",
            names};
  }

 private:
  bool gradient_form_ = false;  // C_p (TPIC, linear tents), not B_p
  bool usf_gradient_ = false;   // C_p from the USF gradient pass (linear tents)
  std::vector<double> node_x_;  // num_nodes * D
};

}  // namespace loam
