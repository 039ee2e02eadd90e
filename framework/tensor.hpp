#pragma once
// Small tensor helpers on Voigt-stored stress (xx yy zz xy yz xz) for D-dimensional kinematics.
#include <array>

#include "force_inline.hpp"
#include "particles.hpp"

namespace loam {

/// Strain increment d = sym(L) dt and spin w = skew(L) dt, embedded in 3x3 (out-of-plane zero).
template <int D>
inline void strain_and_spin(const double* L, size_t stride, size_t p, double dt, double (&d)[3][3],
                            double (&w)[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) d[i][j] = w[i][j] = 0.0;
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      const double lij = L[size_t(i * D + j) * stride + p];
      const double lji = L[size_t(j * D + i) * stride + p];
      d[i][j] = 0.5 * (lij + lji) * dt;
      w[i][j] = 0.5 * (lij - lji) * dt;
    }
}

/// Jaumann co-rotational increment of a symmetric stress: dS = w s - s w (objective rate,
/// Truesdell & Noll); applied with the spin increment w = skew(L) dt.
inline void jaumann_rotation(const double (&w)[3][3], const double (&s)[3][3], double (&ds)[3][3]) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double a = 0;
      for (int k = 0; k < 3; ++k) a += w[i][k] * s[k][j] - s[i][k] * w[k][j];
      ds[i][j] = a;
    }
}

/// Hypoelastic isotropic update with the Jaumann rate, in Voigt form for particle p of a block:
///   sigma += (w sigma - sigma w) + lambda tr(d) I + 2 G d,   d = sym(L) dt, w = skew(L) dt.
/// Written per dimension so the loop over particles vectorises (no 3x3 temporaries in 1D/2D).
/// `s` are the NS stress columns at the block start; L is the block's velocity gradient.
template <int D>
inline void jaumann_elastic_update(double* const* s, const double* L, size_t stride, size_t p,
                                   double dt, double lambda, double two_g) {
  if constexpr (D == 1) {
    const double d = L[p] * dt;
    const double lt = lambda * d;
    s[0][p] += lt + two_g * d;
    s[1][p] += lt;
    s[2][p] += lt;
  } else if constexpr (D == 2) {
    const double dxx = L[p] * dt, dxy = 0.5 * (L[stride + p] + L[2 * stride + p]) * dt;
    const double w = 0.5 * (L[stride + p] - L[2 * stride + p]) * dt;  // w_xy
    const double dyy = L[3 * stride + p] * dt;
    const double lt = lambda * (dxx + dyy);
    const double sxx = s[0][p], syy = s[1][p], sxy = s[3][p];
    s[0][p] = sxx + 2 * w * sxy + lt + two_g * dxx;
    s[1][p] = syy - 2 * w * sxy + lt + two_g * dyy;
    s[2][p] += lt;
    s[3][p] = sxy + w * (syy - sxx) + two_g * dxy;
  } else {
    double d[3][3], w[3][3], m[3][3], r[3][3];
    strain_and_spin<3>(L, stride, p, dt, d, w);
    const double sv[6] = {s[0][p], s[1][p], s[2][p], s[3][p], s[4][p], s[5][p]};
    m[0][0] = sv[0], m[1][1] = sv[1], m[2][2] = sv[2];
    m[0][1] = m[1][0] = sv[3], m[1][2] = m[2][1] = sv[4], m[0][2] = m[2][0] = sv[5];
    jaumann_rotation(w, m, r);
    const double lt = lambda * (d[0][0] + d[1][1] + d[2][2]);
    s[0][p] = sv[0] + r[0][0] + lt + two_g * d[0][0];
    s[1][p] = sv[1] + r[1][1] + lt + two_g * d[1][1];
    s[2][p] = sv[2] + r[2][2] + lt + two_g * d[2][2];
    s[3][p] = sv[3] + r[0][1] + two_g * d[0][1];
    s[4][p] = sv[4] + r[1][2] + two_g * d[1][2];
    s[5][p] = sv[5] + r[0][2] + two_g * d[0][2];
  }
}

template <int NS>
inline void voigt_to_matrix(const double (&v)[NS], double (&s)[3][3]) {
  s[0][0] = v[0], s[1][1] = v[1], s[2][2] = v[2];
  s[0][1] = s[1][0] = NS > 3 ? v[3] : 0.0;
  s[1][2] = s[2][1] = NS > 4 ? v[4] : 0.0;
  s[0][2] = s[2][0] = NS > 5 ? v[5] : 0.0;
}

/// Volume ratio det(I + L dt) of one explicit step: V^{n+1} = det(I + L dt) V^n, the exact
/// Jacobian of the particle motion x^{n+1} = x^n + v dt in a linear velocity field.
template <int D>
LOAM_FORCE_INLINE double det_increment(const double (&l)[D][D], double dt) {
  if constexpr (D == 1) {
    return 1.0 + l[0][0] * dt;
  } else if constexpr (D == 2) {
    return (1.0 + l[0][0] * dt) * (1.0 + l[1][1] * dt) - l[0][1] * l[1][0] * dt * dt;
  } else {
    double f[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) f[i][j] = (i == j ? 1.0 : 0.0) + l[i][j] * dt;
    return f[0][0] * (f[1][1] * f[2][2] - f[1][2] * f[2][1]) -
           f[0][1] * (f[1][0] * f[2][2] - f[1][2] * f[2][0]) +
           f[0][2] * (f[1][0] * f[2][1] - f[1][1] * f[2][0]);
  }
}

/// det(I + A) - 1 with A = L dt, without the cancellation of det(I + A) - 1 in floating point:
/// tr A + the sum of A's principal 2 x 2 minors + det A: the volume change det_increment - 1
/// of a step where it is small against 1 (F-bar, framework/fbar.hpp, projects it: the
/// projection's round-off then scales with the change, and a rigid spin, a change of
/// (omega dt)^2, stays free of stress).
template <int D>
double volume_change(const double (&l)[D][D], double dt) {
  double a[D][D];
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) a[i][j] = l[i][j] * dt;
  if constexpr (D == 1) {
    return a[0][0];
  } else if constexpr (D == 2) {
    return a[0][0] + a[1][1] + (a[0][0] * a[1][1] - a[0][1] * a[1][0]);
  } else {
    const double minors = a[0][0] * a[1][1] - a[0][1] * a[1][0] + a[0][0] * a[2][2] -
                          a[0][2] * a[2][0] + a[1][1] * a[2][2] - a[1][2] * a[2][1];
    const double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
                       a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
                       a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    return a[0][0] + a[1][1] + a[2][2] + minors + det;
  }
}

/// F^{n+1} = (I + L dt) F^n for particle p of a block; F holds the D*D component columns
/// (F_ij at index i*D + j) at the block start.
template <int D>
LOAM_FORCE_INLINE void update_deformation_gradient(const std::array<double*, D * D>& F,
                                                   const double (&l)[D][D], double dt, int p) {
  double f[D][D];
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) f[i][j] = F[size_t(i * D + j)][p];
  for (int i = 0; i < D; ++i)
    for (int j = 0; j < D; ++j) {
      double sum = f[i][j];
      for (int k = 0; k < D; ++k) sum += l[i][k] * dt * f[k][j];
      F[size_t(i * D + j)][p] = sum;
    }
}

}  // namespace loam
