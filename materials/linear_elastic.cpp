// Isotropic linear elasticity in two large-deformation formulations (parameter `formulation`):
//
// jaumann (default): hypoelastic Cauchy stress with the Jaumann rate,
//   sigma^{n+1} = sigma^n + (w sigma - sigma w) + lambda tr(d) I + 2 G d,
// d = sym(L) dt, w = skew(L) dt. Confined compression to a stretch h/H gives sigma = M ln(h/H)
// (in the limit of small increments; M = lambda + 2G).
//
// hencky: hyperelastic, from the deformation gradient F that the scheme updates,
//   sigma = tau_e / J + R sigma_0 R^T,   tau_e = lambda tr(eps) I + 2 G eps,   eps = 1/2 ln(F F^T),
// with the Kirchhoff stress tau_e of the logarithmic (Hencky) strain of the left stretch,
// J = det F (tr eps = ln J) and R the rotation of the polar decomposition F = R U. The stress is
// a function of F only: confined compression gives J sigma = M ln J for any number of
// increments, a closed deformation cycle returns the initial stress, a rigid rotation rotates it.
//
// Initial stress: sigma_0 is the Cauchy stress a particle has when initialize() runs (a
// geostatic or element-test initial stress; at F = I it is stored as is, in general as
// R^T (sigma - tau_e / J) R so that the stress in place is kept exactly). It is kept in the
// reference frame and turned with the material, as a Cauchy stress: the incremental stiffness at
// the initial state is then C (plus the rotation of sigma_0), the same as jaumann's, whatever
// sigma_0. (A constant Kirchhoff offset, sigma = (tau_0 + tau_e) / J, would instead stiffen
// compression by |sigma_0|: d sigma / d ln J = M + p0 in 1D at J = 1.) The model is exactly
// hyperelastic for a stress-free or isotropic initial stress (energy W_H - p0 (J - 1) per
// reference volume, W_H = 1/2 lambda tr(eps)^2 + G eps:eps); with a deviatoric sigma_0 it is
// still path independent and objective. A body that starts stress free has sigma_0 = 0 and skips
// the rotation.
//
// Tension positive, Voigt xx yy zz xy yz xz. 2D is plane strain (eps_zz = 0, so sigma_zz comes
// from lambda tr(eps)), 1D is laterally confined (sigma_yy = sigma_zz = lambda tr(eps) / J), as
// in docs/verification.md A. The 2D logarithm is closed form (no eigenvectors: eps = 1/2 ln J I +
// beta dev(B)), 1D is scalar; 3D takes the eigenvalues of B = F F^T in closed form and the
// logarithm (and V^-1 for R) by Newton's divided differences, without eigenvectors. An inverted
// particle (det F <= 0) gives a non-finite stress.
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"
#include "materials/isotropic_elasticity.hpp"

namespace loam {

template <int D>
class LinearElastic : public Material<D> {
  static constexpr int NS = Particles<D>::NS;

 public:
  static constexpr const char* name = "linear_elastic";
  static constexpr const char* summary =
      "isotropic linear elasticity: hypoelastic Jaumann rate or hyperelastic Hencky";
  static Schema schema() {
    Schema s = isotropic_elastic_schema(false);
    s.choice("formulation", {"jaumann", "hencky"},
             "jaumann: hypoelastic Cauchy stress with the Jaumann rate (incremental, cheapest); "
             "hencky: hyperelastic from the deformation gradient F, sigma = tau / det F with the "
             "Kirchhoff stress tau = lambda tr(eps) I + 2 G eps of the logarithmic strain "
             "eps = 1/2 ln(F F^T), plus the initial Cauchy stress turned with the material (path "
             "independent, exactly objective; keeps F and the initial stress per particle). "
             "Confined compression to h/H: sigma = M ln(h/H) (jaumann), det(F) sigma = "
             "M ln(h/H) (hencky)")
        .def("jaumann");
    return s;
  }
  explicit LinearElastic(const Params& p)
      : E_(p.real("E")),
        nu_(p.real("nu")),
        rho_(p.real("density")),
        hencky_(p.text("formulation") == "hencky") {
    G_ = E_ / (2 * (1 + nu_));
    lambda_ = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_));
    M_ = lambda_ + 2 * G_;  // constrained (P-wave) modulus
  }

  double density() const override { return rho_; }

  void setup(Simulation<D>& sim, int m, Diagnostics&) override {
    if (!hencky_) return;
    const int set = sim.body_set(m);  // state fields live in the set of the body
    F_ = sim.request_deformation_gradient();
    sigma0_ =
        sim.request_field({"hencky_initial_stress", NS, "Pa",
                           "initial Cauchy stress of the hencky formulation in the reference frame "
                           "(sigma = tau_e / J + R sigma_0 R^T)",
                           Particles<D>::stress_names()},
                          set);
  }

  void initialize(Particles<D>& P, size_t b, size_t e) override {
    if (!hencky_ || sigma0_ < 0) return;
    bool any = false;
    for (size_t i = b; i < e; ++i) {
      double f[D * D], tau[NS], J, R[3][3];
      for (int c = 0; c < D * D; ++c) f[c] = P.col(F_, c)[i];
      kirchhoff(f, tau, J, &R);
      // sigma_0 = R^T (sigma - tau_e / J) R keeps the stress in place exactly (= sigma at F = I).
      double x[NS], s0[NS];
      for (int c = 0; c < NS; ++c) x[c] = P.col(P.stress, c)[i] - tau[c] / J;
      const double Rt[3][3] = {
          {R[0][0], R[1][0], R[2][0]}, {R[0][1], R[1][1], R[2][1]}, {R[0][2], R[1][2], R[2][2]}};
      for (int c = 0; c < NS; ++c) s0[c] = 0;
      add_rotated(Rt, x, s0);
      for (int c = 0; c < NS; ++c) {
        P.col(sigma0_, c)[i] = s0[c];
        any = any || s0[c] != 0;
      }
    }
    prestressed_ = prestressed_ || any;
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    if (!hencky_) return p_wave_speed(P, b, e, M_);
    // 1D tangent: d sigma / d ln J = (M - tau_e) / J, so c^2 = (M - tau_e) / (rho J) with the
    // current density rho = m / V. With |tau_e| / J <= |sigma| + |sigma_0| (Frobenius norms):
    // c^2 <= (M / J + |sigma| + |sigma_0|) / rho, which is sqrt(M / rho) at F = I.
    const double* m = P.col(P.mass);
    const double* V = P.col(P.volume);
    const double* f[D * D];
    const double* s[NS];
    const double* s0[NS];
    for (int c = 0; c < D * D; ++c) f[c] = P.col(F_, c);
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c);
    for (int c = 0; c < NS; ++c) s0[c] = P.col(sigma0_, c);
    const bool pre = prestressed_;
    double c2 = 0;
#pragma omp parallel for reduction(max : c2) schedule(static)
    for (size_t i = b; i < e; ++i) {
      double fi[D * D];
      for (int c = 0; c < D * D; ++c) fi[c] = f[c][i];
      double ss = 0, ss0 = 0;
      for (int c = 0; c < NS; ++c) ss += (c < 3 ? 1.0 : 2.0) * s[c][i] * s[c][i];
      if (pre)
        for (int c = 0; c < NS; ++c) ss0 += (c < 3 ? 1.0 : 2.0) * s0[c][i] * s0[c][i];
      const double J = std::max(det(fi), 1e-300);
      c2 = std::max(c2, (M_ / J + std::sqrt(ss) + std::sqrt(ss0)) * V[i] / std::max(m[i], 1e-300));
    }
    return std::sqrt(c2);
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    if (hencky_) return update_hencky(batch);
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    for (int p = 0; p < batch.count; ++p)
      jaumann_elastic_update<D>(s, batch.L, kBlock, size_t(p), batch.dt, lambda_, 2 * G_);
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    if (!hencky_) return isotropic_elastic_energy(P, b, e, E_, nu_);
    // Per reference volume V0 = V / J: 1/2 x : C^-1 : x with x = tau_e + R sigma_0 R^T, i.e.
    // W_H = 1/2 lambda tr(eps)^2 + G eps:eps (exact, its rate is J sigma : d) for a stress-free
    // start; with an initial stress it adds sigma_0' : eps + 1/2 sigma_0 : C^-1 : sigma_0, the
    // form of the jaumann energy (1/2 sigma : C^-1 : sigma), whose rate matches the stress power
    // to first order in the strain.
    const double* V = P.col(P.volume);
    double sum = 0;
    for (size_t i = b; i < e; ++i) {
      double fi[D * D], x[NS], J, R[3][3], sv[6] = {0, 0, 0, 0, 0, 0};
      for (int c = 0; c < D * D; ++c) fi[c] = P.col(F_, c)[i];
      if (prestressed_) {
        kirchhoff(fi, x, J, &R);
        double s0[NS];
        for (int c = 0; c < NS; ++c) s0[c] = P.col(sigma0_, c)[i];
        add_rotated(R, s0, x);
      } else {
        kirchhoff(fi, x, J, nullptr);
      }
      for (int c = 0; c < NS; ++c) sv[c] = x[c];
      sum += V[i] / J * isotropic_energy_density(sv, E_, nu_);
    }
    return sum;
  }

 private:
  /// atanh(u) / u, by its series for small |u|.
  static double atanh_ratio(double u) {
    const double u2 = u * u;
    return std::fabs(u) < 1e-3 ? 1 + u2 * (1.0 / 3 + u2 * (1.0 / 5 + u2 / 7)) : std::atanh(u) / u;
  }

  static double det(const double (&f)[D * D]) {
    if constexpr (D == 1) {
      return f[0];
    } else if constexpr (D == 2) {
      return f[0] * f[3] - f[1] * f[2];
    } else {
      return f[0] * (f[4] * f[8] - f[5] * f[7]) - f[1] * (f[3] * f[8] - f[5] * f[6]) +
             f[2] * (f[3] * f[7] - f[4] * f[6]);
    }
  }

  /// Elastic Kirchhoff stress tau_e = lambda tr(eps) I + 2 G eps (Voigt) of eps = 1/2 ln(F F^T),
  /// J = det F, and if R != nullptr the rotation of F = R U (3x3, out-of-plane identity).
  void kirchhoff(const double (&f)[D * D], double (&tau)[NS], double& J, double (*R)[3][3]) const {
    if (R)
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) (*R)[i][j] = i == j ? 1.0 : 0.0;
    if constexpr (D == 1) {
      J = f[0];
      const double e = std::log(J);
      tau[0] = M_ * e;
      tau[1] = tau[2] = lambda_ * e;
    } else if constexpr (D == 2) {
      // B = F F^T = m I + [[h, c], [c, -h]] with eigenvalues m +- r. A function of a 2x2
      // symmetric matrix is linear in it: 1/2 ln B = 1/4 ln(det B) I + beta dev(B), i.e.
      // eps = 1/2 ln J I + beta dev(B), beta = (ln(m + r) - ln(m - r)) / (4 r) = atanh(r/m)/(2 r),
      // evaluated by its series where r/m is small (nearly equal stretches).
      J = f[0] * f[3] - f[1] * f[2];
      const double a = f[0] * f[0] + f[1] * f[1], d = f[2] * f[2] + f[3] * f[3];
      const double c = f[0] * f[2] + f[1] * f[3];
      const double m = 0.5 * (a + d), h = 0.5 * (a - d);
      const double r = std::sqrt(h * h + c * c), x = r / m;
      const double beta = atanh_ratio(x) / (2 * m);
      const double lnJ = std::log(J);
      const double lt = lambda_ * lnJ, g2 = 2 * G_;
      tau[0] = lt + g2 * (0.5 * lnJ + beta * h);
      tau[1] = lt + g2 * (0.5 * lnJ - beta * h);
      tau[2] = lt;
      tau[3] = g2 * beta * c;
      if (R) {
        // Polar rotation angle of a 2x2 F with det F > 0: tan(theta) = (F_yx - F_xy)/(F_xx + F_yy).
        const double co = f[0] + f[3], si = f[2] - f[1], n = std::hypot(co, si);
        (*R)[0][0] = (*R)[1][1] = co / n;
        (*R)[1][0] = si / n;
        (*R)[0][1] = -si / n;
      }
    } else {
      J = det(f);
      // B = F F^T and its eigenvalues x >= y >= z in closed form (trigonometric, Smith 1961).
      double B[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = i; j < 3; ++j)
          B[i][j] = B[j][i] =
              f[i * 3] * f[j * 3] + f[i * 3 + 1] * f[j * 3 + 1] + f[i * 3 + 2] * f[j * 3 + 2];
      const double m = (B[0][0] + B[1][1] + B[2][2]) / 3;
      const double k0 = B[0][0] - m, k1 = B[1][1] - m, k2 = B[2][2] - m;
      const double p2 = (k0 * k0 + k1 * k1 + k2 * k2 +
                         2 * (B[0][1] * B[0][1] + B[1][2] * B[1][2] + B[0][2] * B[0][2])) /
                        6;
      double x = m, y = m, z = m;
      if (p2 > 1e-40 * m * m) {  // else isotropic to round-off: the nodes x = y = z = m do
        const double p = std::sqrt(p2);
        const double detK = k0 * (k1 * k2 - B[1][2] * B[1][2]) -
                            B[0][1] * (B[0][1] * k2 - B[1][2] * B[0][2]) +
                            B[0][2] * (B[0][1] * B[1][2] - k1 * B[0][2]);
        const double phi = std::acos(std::clamp(detK / (2 * p2 * p), -1.0, 1.0)) / 3;
        x = m + 2 * p * std::cos(phi);
        z = m + 2 * p * std::cos(phi + 2.0943951023931957);  // + 2 pi / 3
        y = 3 * m - x - z;
      }
      // f(B) for f = 1/2 ln by Newton's interpolation at the eigenvalues (Cayley-Hamilton):
      //   f(B) = f(x) I + f[x,y] A + f[x,y,z] A C,   A = B - x I, C = B - y I = A + (x - y) I.
      // Exact for any spectrum; the divided differences are evaluated without cancellation
      // (f[x,y] = atanh(u)/u / (x + y), u = (x - y)/(x + y)), and where x ~ z the last term is
      // O((x - z)^2) so f[x,y,z] -> f''/2 is enough. Inaccurate eigenvalues of a nearly repeated
      // spectrum (the trigonometric formula loses digits there) only enter through
      // f[x,y,z,b] (b - x)(b - y)(b - z) at the true eigenvalues b: round-off either way.
      const double fx = 0.5 * std::log(x);
      const double fxy = atanh_ratio((x - y) / (x + y)) / (x + y);
      const double fyz = atanh_ratio((y - z) / (y + z)) / (y + z);
      const double fxyz = x - z > 1e-6 * x ? (fxy - fyz) / (x - z) : -0.25 / (y * y);
      double A[3][3], AC[3][3];
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) A[i][j] = B[i][j] - (i == j ? x : 0.0);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          AC[i][j] = A[i][0] * A[0][j] + A[i][1] * A[1][j] + A[i][2] * A[2][j] + (x - y) * A[i][j];
      static constexpr int I[6] = {0, 1, 2, 0, 1, 0}, Jx[6] = {0, 1, 2, 1, 2, 2};
      const double lt = lambda_ * std::log(J), g2 = 2 * G_;
      for (int c = 0; c < 6; ++c) {
        const double eps = (c < 3 ? fx : 0.0) + fxy * A[I[c]][Jx[c]] + fxyz * AC[I[c]][Jx[c]];
        tau[c] = (c < 3 ? lt : 0.0) + g2 * eps;
      }
      if (R) {
        // R = V^-1 F with V^-1 = g(B), g(b) = b^-1/2, whose divided differences have closed
        // forms (a, b, c the square roots of x, y, z): g[x,y] = -1/(a b (a + b)),
        // g[x,y,z] = (a + b + c) / (a b c (a + b)(b + c)(a + c)).
        const double a = std::sqrt(x), bb = std::sqrt(y), c = std::sqrt(z);
        const double gx = 1 / a, gxy = -1 / (a * bb * (a + bb));
        const double gxyz = (a + bb + c) / (a * bb * c * (a + bb) * (bb + c) * (a + c));
        double Vi[3][3];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            Vi[i][j] = (i == j ? gx : 0.0) + gxy * A[i][j] + gxyz * AC[i][j];
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            (*R)[i][j] = Vi[i][0] * f[j] + Vi[i][1] * f[3 + j] + Vi[i][2] * f[6 + j];
      }
    }
  }

  /// out += R t R^T for a Voigt tensor t (NS components).
  static void add_rotated(const double (&R)[3][3], const double (&t)[NS], double (&out)[NS]) {
    if constexpr (D == 1) {
      for (int c = 0; c < NS; ++c) out[c] += t[c];  // 1D: no rotation
    } else {
      double m[3][3], rm[3][3];
      voigt_to_matrix<NS>(t, m);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
          double a = 0;
          for (int k = 0; k < 3; ++k) a += R[i][k] * m[k][j];
          rm[i][j] = a;
        }
      static constexpr int I[6] = {0, 1, 2, 0, 1, 0}, Jx[6] = {0, 1, 2, 1, 2, 2};
      for (int c = 0; c < NS; ++c) {
        double a = 0;
        for (int k = 0; k < 3; ++k) a += rm[I[c]][k] * R[Jx[c]][k];
        out[c] += a;
      }
    }
  }

  void update_hencky(const MaterialBatch<D>& batch) const {
    Particles<D>& P = *batch.particles;
    double* s[NS];
    const double* f[D * D];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    for (int c = 0; c < D * D; ++c) f[c] = P.col(F_, c) + batch.begin;
    if (!prestressed_) {
      for (int p = 0; p < batch.count; ++p) {
        double fp[D * D], tau[NS], J;
        for (int c = 0; c < D * D; ++c) fp[c] = f[c][p];
        kirchhoff(fp, tau, J, nullptr);
        const double inv = 1 / J;
        for (int c = 0; c < NS; ++c) s[c][p] = tau[c] * inv;
      }
      return;
    }
    const double* s0[NS];
    for (int c = 0; c < NS; ++c) s0[c] = P.col(sigma0_, c) + batch.begin;
    for (int p = 0; p < batch.count; ++p) {
      double fp[D * D], tau[NS], J, R[3][3], sp[NS], out[NS];
      for (int c = 0; c < D * D; ++c) fp[c] = f[c][p];
      kirchhoff(fp, tau, J, &R);
      const double inv = 1 / J;
      for (int c = 0; c < NS; ++c) out[c] = tau[c] * inv, sp[c] = s0[c][p];
      add_rotated(R, sp, out);
      for (int c = 0; c < NS; ++c) s[c][p] = out[c];
    }
  }

  double E_, nu_, rho_, G_, lambda_, M_;
  bool hencky_ = false;
  bool prestressed_ = false;  // some particle has a nonzero sigma_0 (else skip the rotation)
  int F_ = -1, sigma0_ = -1;  // particle fields (hencky only)
};

LOAM_REGISTER(Material, LinearElastic)

}  // namespace loam
