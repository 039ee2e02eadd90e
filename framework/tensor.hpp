#pragma once
// Small tensor helpers on Voigt-stored stress (xx yy zz xy yz xz) for D-dimensional kinematics.
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

template <int NS>
inline void voigt_to_matrix(const double (&v)[NS], double (&s)[3][3]) {
  s[0][0] = v[0], s[1][1] = v[1], s[2][2] = v[2];
  s[0][1] = s[1][0] = NS > 3 ? v[3] : 0.0;
  s[1][2] = s[2][1] = NS > 4 ? v[4] : 0.0;
  s[0][2] = s[2][0] = NS > 5 ? v[5] : 0.0;
}

}  // namespace loam
