#pragma once
// The Mohr-Coulomb principal-stress return mapping shared by the mohr_coulomb and
// strain_softening_mc materials, and what they share with drucker_prager: the Jaumann elastic
// trial, the reduced friction angle, the dilation angle's schema.
//
// Sign convention: Cauchy stress, TENSION POSITIVE. Principal stresses are ordered
// s1 >= s2 >= s3 (s1 the most tensile, s3 the most compressive). Angles in degrees.
//
// Return mapping (closed form, exact for linear elasticity):
//   yield     f = k s1 - s3 - sc,  k = (1 + sin phi)/(1 - sin phi), sc = 2 c cos phi/(1 - sin phi)
//             (= (s1 - s3) + (s1 + s3) sin phi - 2 c cos phi, divided by 1 - sin phi)
//   potential g = m s1 - s3,        m = (1 + sin psi)/(1 - sin psi)
// Principal elastic matrix De = lambda 1 1^T + 2 G I; flow vectors b = dg/ds.
//   - main plane: s = s_tr - dl De b1, b1 = (m, 0, -1), dl = f(s_tr)/(a1.De b1), a1 = (k, 0, -1);
//     accepted if the result keeps s1 >= s2 >= s3.
//   - otherwise an edge, chosen as in de Souza Neto, Peric & Owen (2008) Box 8.5:
//     (1 - sin psi) s1 - 2 s2 + (1 + sin psi) s3 > 0 -> s2 = s3 edge (triaxial extension, second
//     surface a = (k, -1, 0), b = (m, -1, 0)), else s1 = s2 edge (triaxial compression,
//     a = (0, k, -1), b = (0, m, -1)). Two multipliers from the 2x2 system
//     [a_i.De b_j] dl_j = f_i(s_tr); accepted if the result is not beyond the apex.
//   - otherwise the apex s1 = s2 = s3 = sc/(k - 1) = c/tan(phi) (no apex when phi = 0).
// Tension cutoff T (default: the apex, i.e. none beyond Mohr-Coulomb; none when phi = 0; a
// larger T is capped at the apex). When T is below the apex and the Mohr-Coulomb result has
// s1 > T, the return solves the Koiter conditions exactly (linear elasticity) over the
// active-set combinations of the Mohr-Coulomb planes (b as above) and the Rankine planes
// s_i <= T (associated, b = e_i), taking the first combination with all multipliers >= 0, every
// surface <= 0 and the order s1 >= s2 >= s3 kept; as a last resort all principal stresses are
// capped at T.
// Equivalent plastic deviatoric strain increment: deq = sqrt(2/3 e^p : e^p), e^p the deviatoric
// part of the principal plastic strain increment sum_i dl_i b_i (the apex and the last-resort
// cap use De^-1 (s_tr - s)).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "framework/diagnostics.hpp"
#include "framework/material.hpp"
#include "framework/params.hpp"
#include "framework/tensor.hpp"
#include "plausible.hpp"

namespace loam {

/// Strength reduction by a factor F (docs/strength_reduction.md): the friction angle (degrees)
/// whose tangent is tan(phi) / F, as c / F is the reduced cohesion (Dawson et al. 1999).
inline double reduced_friction_angle(double phi_deg, double F) {
  return std::atan(std::tan(phi_deg * M_PI / 180.0) / F) * 180.0 / M_PI;
}

/// The dilation angle `psi` (degrees, 0 <= psi < 90) of a frictional model's schema, and the
/// located error when it exceeds the friction angle `phi` (mohr_coulomb, drucker_prager).
inline void add_dilation_angle(Schema& s) {
  plausible_angle(s.real("psi", "deg", "dilation angle (non-associated flow; psi <= phi)")
                      .required()
                      .min(0)
                      .below(90));
  s.check([](const Params& p, Diagnostics& d) {
    if (p.real("psi") > p.real("phi"))
      d.error(p.where("psi"), p.path("psi"),
              "dilation angle psi = " + format_number(p.real("psi")) +
                  " must not exceed the friction angle phi = " + format_number(p.real("phi")));
  });
}

class MohrCoulombSurface {
 public:
  using Vec3 = Eigen::Vector3d;

  /// Elastic constants E (Pa), nu; cohesion c (Pa); friction and dilation angles (degrees,
  /// 0 <= psi <= phi < 90); tension cutoff (Pa, tension positive; infinity = the apex).
  MohrCoulombSurface(double E, double nu, double c, double phi_deg, double psi_deg,
                     double tension_cutoff = std::numeric_limits<double>::infinity())
      : E_(E) {
    const double deg = M_PI / 180.0;
    const double sphi = std::sin(phi_deg * deg), cphi = std::cos(phi_deg * deg);
    const double spsi = std::sin(psi_deg * deg);
    const double G = E / (2 * (1 + nu));
    const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
    sin_psi_ = spsi;
    k_ = (1 + sphi) / (1 - sphi);
    m_ = (1 + spsi) / (1 - spsi);
    sc_ = 2 * c * cphi / (1 - sphi);
    has_apex_ = k_ > 1;
    apex_ = has_apex_ ? sc_ / (k_ - 1) : std::numeric_limits<double>::infinity();
    cutoff_ = std::min(tension_cutoff, apex_);
    De_ = Eigen::Matrix3d::Constant(lambda) + 2 * G * Eigen::Matrix3d::Identity();
    // Mohr-Coulomb planes for ordered principal stresses: main, s1 = s2 edge, s2 = s3 edge.
    mc_[0] = {Vec3(k_, 0, -1), Vec3(m_, 0, -1), sc_};
    mc_[1] = {Vec3(0, k_, -1), Vec3(0, m_, -1), sc_};
    mc_[2] = {Vec3(k_, -1, 0), Vec3(m_, -1, 0), sc_};
    for (int i = 0; i < 3; ++i) {
      Vec3 e = Vec3::Zero();
      e[i] = 1;
      rk_[i] = {e, e, cutoff_};
    }
  }

  /// Mohr-Coulomb yield value k s1 - s3 - sc of ordered principal stresses (tension positive).
  double yield(const Vec3& s) const { return k_ * s[0] - s[2] - sc_; }
  /// The apex c/tan(phi) (infinity when phi = 0) and the effective tension cutoff (<= apex).
  double apex() const { return apex_; }
  double cutoff() const { return cutoff_; }

  /// True if the ordered principal trial stress `str` is admissible (within round-off).
  bool elastic(const Vec3& str) const {
    const double tol = 1e-12 * (std::fabs(sc_) + str.cwiseAbs().maxCoeff());
    return yield(str) <= tol && str[0] <= cutoff_ + tol;
  }

  /// Return an inadmissible ordered principal trial stress `str` to `s` (ordered); deq the
  /// equivalent plastic deviatoric strain increment. Call only when !elastic(str).
  void return_principal(const Vec3& str, Vec3& s, double& deq) const {
    const double tol = 1e-12 * (std::fabs(sc_) + str.cwiseAbs().maxCoeff());
    Vec3 dep;
    mc_return(str, s, dep);
    if (s[0] > cutoff_ + tol) cutoff_return(str, s, dep);
    const Vec3 dev = dep - Vec3::Constant(dep.sum() / 3);
    deq = std::sqrt(2.0 / 3.0 * dev.squaredNorm());
  }

  /// Return the trial stress `t` in place; false if it was elastic (t unchanged, deq untouched).
  bool return_map(Eigen::Matrix3d& t, double& deq) const {
    const Principal pr(t);
    if (elastic(pr.values)) return false;
    Vec3 s;
    return_principal(pr.values, s, deq);
    pr.compose(s, t);
    return true;
  }

  /// Ordered principal stresses s1 >= s2 >= s3 of a symmetric matrix and their directions.
  struct Principal {
    explicit Principal(const Eigen::Matrix3d& t) : es(t) {
      const Vec3 ev = es.eigenvalues();  // ascending
      values = Vec3(ev[2], ev[1], ev[0]);
    }
    /// t = Q diag(s) Q^T with Q's columns the directions of s1, s2, s3. (An output argument,
    /// not a return value: Eigen evaluates the two forms with different round-off.)
    void compose(const Vec3& s, Eigen::Matrix3d& t) const {
      Eigen::Matrix3d Q;
      Q.col(0) = es.eigenvectors().col(2);
      Q.col(1) = es.eigenvectors().col(1);
      Q.col(2) = es.eigenvectors().col(0);
      t = Q * s.asDiagonal() * Q.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
    Vec3 values;
  };

 private:
  /// A plane in principal stress space: a.s <= rhs, plastic flow direction b.
  struct Plane {
    Vec3 a, b;
    double rhs;
  };

  /// Closed-form Koiter return onto planes[0..n) (n <= 3); false if the system is singular.
  bool solve(const Vec3& str, const Plane* const* pl, int n, Vec3& s, Vec3& dl) const {
    Eigen::Matrix3d A = Eigen::Matrix3d::Identity();
    Vec3 rhs = Vec3::Zero();
    for (int i = 0; i < n; ++i) {
      rhs[i] = pl[i]->a.dot(str) - pl[i]->rhs;
      for (int j = 0; j < n; ++j) A(i, j) = pl[i]->a.dot(De_ * pl[j]->b);
    }
    Eigen::FullPivLU<Eigen::Matrix3d> lu(A);
    if (!lu.isInvertible()) return false;
    dl = lu.solve(rhs);
    s = str;
    for (int i = 0; i < n; ++i) s -= dl[i] * (De_ * pl[i]->b);
    return true;
  }

  /// Mohr-Coulomb return (main plane, edge, apex); dep the principal plastic strain increment.
  void mc_return(const Vec3& str, Vec3& s, Vec3& dep) const {
    const double tol = 1e-12 * (std::fabs(sc_) + str.cwiseAbs().maxCoeff());
    Vec3 dl;
    const Plane* pl[2] = {&mc_[0], nullptr};
    solve(str, pl, 1, s, dl);
    if (s[0] + tol >= s[1] && s[1] + tol >= s[2]) {
      dep = dl[0] * mc_[0].b;
      return;
    }
    const bool extension = (1 - sin_psi_) * str[0] - 2 * str[1] + (1 + sin_psi_) * str[2] > 0;
    pl[1] = extension ? &mc_[2] : &mc_[1];
    if (solve(str, pl, 2, s, dl) && (!has_apex_ || s[0] + tol >= s[2])) {
      dep = dl[0] * mc_[0].b + dl[1] * pl[1]->b;
      return;
    }
    s = Vec3::Constant(apex_);  // apex (only reached when phi > 0)
    dep = De_.inverse() * (str - s);
  }

  /// Combined Mohr-Coulomb and Rankine (s_i <= T) return when the cutoff is below the apex.
  void cutoff_return(const Vec3& str, Vec3& s, Vec3& dep) const {
    const double tol = 1e-10 * (std::fabs(sc_) + std::fabs(cutoff_) + str.cwiseAbs().maxCoeff());
    const Plane* all[6] = {&rk_[0], &rk_[1], &rk_[2], &mc_[0], &mc_[1], &mc_[2]};
    auto admissible = [&](const Vec3& x) {
      if (x[0] + tol < x[1] || x[1] + tol < x[2]) return false;
      for (const Plane* q : all)
        if (q->a.dot(x) - q->rhs > tol) return false;
      return true;
    };
    for (int n = 1; n <= 3; ++n)
      for (int mask = 1; mask < 64; ++mask) {
        if (__builtin_popcount(unsigned(mask)) != n) continue;
        const Plane* pl[3];
        int k = 0;
        for (int i = 0; i < 6; ++i)
          if (mask & (1 << i)) pl[k++] = all[i];
        Vec3 x, dl;
        if (!solve(str, pl, n, x, dl)) continue;
        if (dl.head(n).minCoeff() < -tol / std::max(E_, 1.0)) continue;
        if (!admissible(x)) continue;
        s = x;
        dep = Vec3::Zero();
        for (int i = 0; i < n; ++i) dep += dl[i] * pl[i]->b;
        return;
      }
    s = s.cwiseMin(cutoff_);
    std::sort(s.data(), s.data() + 3, std::greater<double>());
    dep = De_.inverse() * (str - s);
  }

  double E_;
  double sin_psi_ = 0, k_ = 1, m_ = 1, sc_ = 0, apex_ = 0, cutoff_ = 0;
  bool has_apex_ = false;
  Eigen::Matrix3d De_;
  Plane mc_[3], rk_[3];
};

/// Elastic trial stress of particle p of a batch, hypoelastic with the Jaumann rate:
///   sigma_tr = sigma + (w sigma - sigma w) + lambda tr(d) I + 2 G d,  d = sym(L) dt,
///   w = skew(L) dt; `s` are the NS stress columns at the batch start.
template <int D>
Eigen::Matrix3d jaumann_trial_stress(double* const* s, const MaterialBatch<D>& batch, int p,
                                     double lambda, double G) {
  constexpr int NS = Particles<D>::NS;
  double d[3][3], w[3][3], m[3][3], r[3][3];
  strain_and_spin<D>(batch.L, kBlock, size_t(p), batch.dt, d, w);
  double sv[NS];
  for (int c = 0; c < NS; ++c) sv[c] = s[c][p];
  voigt_to_matrix<NS>(sv, m);
  jaumann_rotation(w, m, r);
  const double lt = lambda * (d[0][0] + d[1][1] + d[2][2]);
  Eigen::Matrix3d tr;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      tr(i, j) = m[i][j] + r[i][j] + 2 * G * d[i][j] + (i == j ? lt : 0.0);
  return tr;
}

/// Store a 3x3 stress into the Voigt columns of particle p (the components the dimension keeps).
template <int D>
void store_stress(double* const* s, int p, const Eigen::Matrix3d& t) {
  constexpr int NS = Particles<D>::NS;
  s[0][p] = t(0, 0), s[1][p] = t(1, 1), s[2][p] = t(2, 2);
  if constexpr (NS > 3) s[3][p] = t(0, 1);
  if constexpr (NS > 5) s[4][p] = t(1, 2), s[5][p] = t(0, 2);
}

}  // namespace loam
