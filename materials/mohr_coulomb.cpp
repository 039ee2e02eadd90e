// Mohr-Coulomb elastoplasticity (perfectly plastic, non-associated) with linear isotropic
// elasticity, hypoelastic with the Jaumann stress rate, and an optional tension cutoff.
//
// Sign convention: Cauchy stress, TENSION POSITIVE (as every loam material), Voigt order
// xx yy zz xy yz xz; 1D stores xx yy zz (laterally confined), 2D is plane strain and stores
// xx yy zz xy, 3D stores all six. Principal stresses are ordered s1 >= s2 >= s3 (s1 the most
// tensile, s3 the most compressive). Angles phi (friction) and psi (dilation) are in degrees.
//
// Update per step, with d = sym(L) dt and w = skew(L) dt:
//   1. sigma_tr = sigma + (w sigma - sigma w) + lambda tr(d) I + 2 G d        (elastic trial)
//   2. eigen-decomposition sigma_tr = V diag(s1, s2, s3) V^T (Eigen SelfAdjointEigenSolver)
//   3. return mapping in principal stresses, closed form (exact for linear elasticity):
//        yield     f = k s1 - s3 - sc,  k = (1 + sin phi)/(1 - sin phi),
//                                        sc = 2 c cos phi/(1 - sin phi)
//                  (= (s1 - s3) + (s1 + s3) sin phi - 2 c cos phi, divided by 1 - sin phi)
//        potential g = m s1 - s3,        m = (1 + sin psi)/(1 - sin psi)
//      Principal elastic matrix De = lambda 1 1^T + 2 G I; flow vectors b = dg/ds.
//      - main plane: s = s_tr - dl De b1, b1 = (m, 0, -1), dl = f(s_tr)/(a1.De b1),
//        a1 = (k, 0, -1); accepted if the result keeps s1 >= s2 >= s3.
//      - otherwise an edge, chosen as in de Souza Neto, Peric & Owen (2008) Box 8.5:
//        (1 - sin psi) s1 - 2 s2 + (1 + sin psi) s3 > 0 -> s2 = s3 edge (triaxial extension,
//        second surface a = (k, -1, 0), b = (m, -1, 0)), else s1 = s2 edge (triaxial compression,
//        a = (0, k, -1), b = (0, m, -1)). Two multipliers from the 2x2 system
//        [a_i.De b_j] dl_j = f_i(s_tr); accepted if the result is not beyond the apex.
//      - otherwise the apex s1 = s2 = s3 = sc/(k - 1) = c/tan(phi) (no apex when phi = 0).
//   4. Tension cutoff T (default: the apex, i.e. none beyond Mohr-Coulomb; none when phi = 0).
//      When T is below the apex and the Mohr-Coulomb result has s1 > T, the return solves the
//      Koiter conditions exactly (linear elasticity) over the active-set combinations of the
//      Mohr-Coulomb planes (b as above) and the Rankine planes s_i <= T (associated, b = e_i),
//      taking the first combination with all multipliers >= 0, every surface <= 0 and the
//      order s1 >= s2 >= s3 kept; as a last resort all principal stresses are capped at T.
//   5. sigma = V diag(s) V^T.
// State: plastic_strain_eq += sqrt(2/3 e^p : e^p), e^p the deviatoric part of the principal
// plastic strain increment sum_i dl_i b_i (the apex uses De^-1 (s_tr - s)).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/diagnostics.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"

namespace loam {

namespace mc_detail {

using Vec3 = Eigen::Vector3d;

/// A plane in principal stress space: a.s <= rhs, plastic flow direction b.
struct Plane {
  Vec3 a, b;
  double rhs;
};

}  // namespace mc_detail

template <int D>
class MohrCoulomb : public Material<D> {
  using Vec3 = mc_detail::Vec3;
  using Plane = mc_detail::Plane;

 public:
  static constexpr const char* name = "mohr_coulomb";
  static constexpr const char* summary =
      "Mohr-Coulomb plasticity (c, phi, psi, tension cutoff), linear elastic, Jaumann rate; "
      "exact principal-stress return (plane, edges, apex)";
  static Schema schema() {
    Schema s;
    s.real("E", "Pa", "Young's modulus").required().positive();
    s.real("nu", "-", "Poisson's ratio").required().above(-1).below(0.5);
    s.real("density", "kg/m^3", "mass density").required().positive();
    s.real("c", "Pa", "cohesion").required().non_negative();
    s.real("phi", "deg", "friction angle").required().min(0).below(90);
    s.real("psi", "deg", "dilation angle (non-associated flow; psi <= phi)")
        .required()
        .min(0)
        .below(90);
    s.real("tension_cutoff", "Pa",
           "largest principal stress (tension positive); default: the Mohr-Coulomb apex "
           "c/tan(phi), none when phi = 0")
        .non_negative();
    s.check([](const Params& p, Diagnostics& d) {
      if (p.real("psi") > p.real("phi"))
        d.error(p.where("psi"), p.path("psi"),
                "dilation angle psi = " + format_number(p.real("psi")) +
                    " must not exceed the friction angle phi = " + format_number(p.real("phi")));
    });
    return s;
  }

  explicit MohrCoulomb(const Params& p)
      : E_(p.real("E")), nu_(p.real("nu")), rho_(p.real("density")), c_(p.real("c")) {
    const double deg = M_PI / 180.0;
    const double sphi = std::sin(p.real("phi") * deg), cphi = std::cos(p.real("phi") * deg);
    const double spsi = std::sin(p.real("psi") * deg);
    G_ = E_ / (2 * (1 + nu_));
    lambda_ = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_));
    M_ = lambda_ + 2 * G_;
    sin_psi_ = spsi;
    k_ = (1 + sphi) / (1 - sphi);
    m_ = (1 + spsi) / (1 - spsi);
    sc_ = 2 * c_ * cphi / (1 - sphi);
    has_apex_ = k_ > 1;
    apex_ = has_apex_ ? sc_ / (k_ - 1) : std::numeric_limits<double>::infinity();
    cutoff_ = p.has("tension_cutoff") ? std::min(p.real("tension_cutoff"), apex_) : apex_;
    De_ = Eigen::Matrix3d::Constant(lambda_) + 2 * G_ * Eigen::Matrix3d::Identity();
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

  double density() const override { return rho_; }

  void setup(Simulation<D>& sim, int, Diagnostics&) override {
    eq_ = sim.particles.request({"plastic_strain_eq",
                                 1,
                                 "-",
                                 "equivalent plastic deviatoric strain sqrt(2/3 e:e), accumulated",
                                 {}});
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    return p_wave_speed(P, b, e, M_);  // elastic P-wave speed bounds the plastic one
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    double* eq = eq_ >= 0 ? P.col(eq_) + batch.begin : nullptr;
    for (int p = 0; p < batch.count; ++p) {
      double d[3][3], w[3][3], m[3][3], r[3][3];
      strain_and_spin<D>(batch.L, kBlock, size_t(p), batch.dt, d, w);
      double sv[NS];
      for (int c = 0; c < NS; ++c) sv[c] = s[c][p];
      voigt_to_matrix<NS>(sv, m);
      jaumann_rotation(w, m, r);
      const double lt = lambda_ * (d[0][0] + d[1][1] + d[2][2]);
      Eigen::Matrix3d tr;
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
          tr(i, j) = m[i][j] + r[i][j] + 2 * G_ * d[i][j] + (i == j ? lt : 0.0);
      double deq = 0;
      if (return_map(tr, deq) && eq) eq[p] += deq;
      s[0][p] = tr(0, 0), s[1][p] = tr(1, 1), s[2][p] = tr(2, 2);
      if constexpr (NS > 3) s[3][p] = tr(0, 1);
      if constexpr (NS > 5) s[4][p] = tr(1, 2), s[5][p] = tr(0, 2);
    }
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    return isotropic_elastic_energy(P, b, e, E_, nu_);
  }

 private:
  /// Mohr-Coulomb yield value of ordered principal stresses (tension positive).
  double yield(const Vec3& s) const { return k_ * s[0] - s[2] - sc_; }

  /// Return the trial stress `t` in place; false if it was elastic (t unchanged).
  bool return_map(Eigen::Matrix3d& t, double& deq) const {
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(t);
    const Vec3 ev = es.eigenvalues();  // ascending
    const Vec3 str(ev[2], ev[1], ev[0]);
    const double tol = 1e-12 * (std::fabs(sc_) + str.cwiseAbs().maxCoeff());
    if (yield(str) <= tol && str[0] <= cutoff_ + tol) return false;
    Vec3 s, dep;
    mc_return(str, s, dep);
    if (s[0] > cutoff_ + tol) cutoff_return(str, s, dep);
    const Vec3 dev = dep - Vec3::Constant(dep.sum() / 3);
    deq = std::sqrt(2.0 / 3.0 * dev.squaredNorm());
    Eigen::Matrix3d Q;  // columns: directions of s1, s2, s3
    Q.col(0) = es.eigenvectors().col(2);
    Q.col(1) = es.eigenvectors().col(1);
    Q.col(2) = es.eigenvectors().col(0);
    t = Q * s.asDiagonal() * Q.transpose();
    return true;
  }

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

  double E_, nu_, rho_, c_, G_ = 0, lambda_ = 0, M_ = 0;
  double sin_psi_ = 0, k_ = 1, m_ = 1, sc_ = 0, apex_ = 0, cutoff_ = 0;
  bool has_apex_ = false;
  Eigen::Matrix3d De_;
  Plane mc_[3], rk_[3];
  int eq_ = -1;
};

LOAM_REGISTER(Material, MohrCoulomb)

}  // namespace loam
