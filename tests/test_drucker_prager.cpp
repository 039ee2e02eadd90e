// Unit tests of the drucker_prager material at one material point
// (materials/drucker_prager.cpp, docs/verification.md B2), driven through MaterialBatch, and its
// parameter checks through the command line. Formulas use compression positive (sigma'_1 >=
// sigma'_3), the material tension positive.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "cli.hpp"
#include "app/element_test.hpp"
#include "material_point.hpp"

namespace {

constexpr double kE = 20e6, kNu = 0.3, kC = 10e3, kPhi = 30, kPsi = 10;

double rad(double deg) {
  return deg * M_PI / 180;
}

/// Mohr-Coulomb's triaxial-compression peak sigma'_1 at confinement s3 (compression positive).
double mc_peak(double s3, double c, double phi) {
  const double sp = std::sin(rad(phi)), cp = std::cos(rad(phi));
  return s3 * (1 + sp) / (1 - sp) + 2 * c * cp / (1 - sp);
}

/// One material point of drucker_prager with the compression-matched cone unless `extra` says.
struct Point : loam_test::MaterialPoint<3> {
  double eta, xi;  // the cone f = sqrt(J2) + eta p - xi c (tension positive p)
  double c;
  int eq = handle("plastic_strain_eq");

  explicit Point(double c_ = kC, double phi = kPhi, double psi = kPsi,
                 const std::string& extra = "")
      : loam_test::MaterialPoint<3>(
            "{type: drucker_prager, E: " + std::to_string(kE) + ", nu: " + std::to_string(kNu) +
            ", density: 2000, c: " + std::to_string(c_) + ", phi: " + std::to_string(phi) +
            ", psi: " + std::to_string(psi) + extra + "}"),
        c(c_) {
    const double s = std::sin(rad(phi)), den = std::sqrt(3.0) * (3 - s);
    eta = 6 * s / den, xi = 6 * std::cos(rad(phi)) / den;
  }
  double& eqps() { return field(eq); }
  /// The cone's variables from MaterialPoint's p (compression positive) and q = sqrt(3 J2).
  double mean() { return -p(); }
  double sqrt_j2() { return q() / std::sqrt(3.0); }
  /// f over a stress scale (compression-matched cone).
  double yield() {
    const double scale = xi * c + std::fabs(mean()) + sqrt_j2();
    return (sqrt_j2() + eta * mean() - xi * c) / scale;
  }
};

struct Triaxial {
  double peak = 0, ratio = 0, worst_f = 0;
};

/// Drained triaxial compression along x at constant lateral stress s3 (compression positive).
Triaxial drained_triaxial(Point& pt, double s3, double strain, int n) {
  Triaxial r;
  pt.isotropic(-s3);
  const double da = strain / n;
  double e_last = 0;
  for (int i = 0; i < n; ++i) {
    e_last = pt.compress_at_lateral_stress(da, s3, kNu);
    r.peak = std::max(r.peak, -pt.stress(0));
    r.worst_f = std::max(r.worst_f, pt.yield());
  }
  r.ratio = (da - 2 * e_last) / da;  // d eps_v / d eps_1, compression positive
  return r;
}

}  // namespace

TEST_CASE("drucker_prager: drained triaxial peak equals Mohr-Coulomb's with the compression cone",
          "[material][unit][drucker_prager]") {
  // The outer cone passes through Mohr-Coulomb's triaxial-compression states (docs/verification.md
  // B2): the peak sigma'_1 = sigma'_3 (1 + sin phi)/(1 - sin phi) + 2 c cos phi/(1 - sin phi),
  // exact up to round-off (the return is closed form): tolerance 1e-8.
  for (double s3 : {50e3, 100e3, 200e3}) {
    Point pt;
    const auto r = drained_triaxial(pt, s3, 0.05, 1000);
    const double exact = mc_peak(s3, kC, kPhi);
    std::printf(
        "DP triaxial sigma3 %.0f Pa: peak %.6f Pa, Mohr-Coulomb %.6f Pa, rel err %.2e, "
        "max f/scale %.2e\n",
        s3, r.peak, exact, std::fabs(r.peak / exact - 1), r.worst_f);
    CHECK(std::fabs(r.peak / exact - 1) <= 1e-8);
    CHECK(r.worst_f <= 1e-10);
    CHECK(pt.eqps() > 0);
  }
}

TEST_CASE("drucker_prager: dilation at failure in triaxial compression matches psi",
          "[material][unit][drucker_prager]") {
  // g's slope eta_bar from psi, compression-matched: d eps_v / d eps_1 = -2 sin psi/(1 - sin psi)
  // at failure, as Mohr-Coulomb (the material's header derives it). Tolerance 1e-6.
  for (double psi : {0.0, 10.0, 30.0}) {
    Point pt(kC, kPhi, psi);
    const auto r = drained_triaxial(pt, 100e3, 0.05, 1000);
    const double sp = std::sin(rad(psi)), exact = -2 * sp / (1 - sp);
    std::printf("DP triaxial dilation psi %.0f: d eps_v/d eps_1 %.9f, exact %.9f\n", psi, r.ratio,
                exact);
    CHECK(r.ratio == Approx(exact).margin(1e-6));
  }
}

TEST_CASE("drucker_prager: the cone's three matchings give their documented strengths",
          "[material][unit][drucker_prager]") {
  // The cone constants of each matching at phi = 30 deg (de Souza Neto, Peric & Owen 2008,
  // section 6.4.6; the material's header): compression eta = 0.3849, xi = 1.1547; extension
  // 0.2962, 0.8885; plane strain with psi = 0 sin phi, cos phi (0.5, 0.8660). Pure shear from a
  // stress-free state (psi = 0, so p stays 0) must end at sqrt(J2) = xi c, an isotropic extension
  // at the apex xi c / eta: both to 1e-10.
  struct Case {
    const char* match;
    double eta, xi;
  };
  const double s = 0.5, c = std::sqrt(3.0) / 2;
  const Case cases[] = {
      {"compression", 6 * s / (std::sqrt(3.0) * (3 - s)), 6 * c / (std::sqrt(3.0) * (3 - s))},
      {"extension", 6 * s / (std::sqrt(3.0) * (3 + s)), 6 * c / (std::sqrt(3.0) * (3 + s))},
      {"plane_strain", s, c}};
  for (const auto& k : cases) {
    // Pure shear at p = 0 from a stress-free state: the shear strength sqrt(J2) = xi c; an
    // isotropic extension ends at the apex p = xi c / eta.
    Point sh(kC, 30, 0, std::string(", match: ") + k.match);
    sh.isotropic(0);
    for (int i = 0; i < 200; ++i) sh.step({0, 1e-4, 0, 1e-4, 0, 0, 0, 0, 0});
    Point ap(kC, 30, 0, std::string(", match: ") + k.match);
    ap.isotropic(0);
    for (int i = 0; i < 20; ++i) ap.step({1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3});
    std::printf("DP %s: shear strength %.6f Pa (xi c = %.6f), apex %.6f Pa (xi c/eta = %.6f)\n",
                k.match, sh.sqrt_j2(), k.xi * kC, ap.mean(), k.xi * kC / k.eta);
    CHECK(sh.sqrt_j2() == Approx(k.xi * kC).epsilon(1e-10));
    CHECK(ap.mean() == Approx(k.xi * kC / k.eta).epsilon(1e-10));
    CHECK(ap.sqrt_j2() == Approx(0).margin(1e-9 * kC));
  }
}

TEST_CASE("drucker_prager: f <= 0 after every return on a random 3D path, apex included",
          "[material][unit][drucker_prager]") {
  for (auto [phi, psi] : {std::pair{30.0, 10.0}, std::pair{0.0, 0.0}, std::pair{40.0, 40.0}}) {
    Point q(kC, phi, psi);
    q.isotropic(-20e3);
    std::mt19937 rng(7);
    std::normal_distribution<double> g(0.0, 1.0);
    double worst = 0;
    int apex = 0;
    for (int i = 0; i < 3000; ++i) {
      std::vector<double> de(9);
      for (auto& x : de) x = 1e-3 * g(rng);
      if (i % 400 < 40)  // bursts of isotropic extension drive it to the apex
        for (int d = 0; d < 3; ++d) de[size_t(4 * d)] = 2e-3 + 1e-2 * de[size_t(4 * d)];
      else
        de[0] -= 1e-4;
      q.step(de);
      worst = std::max(worst, q.yield());
      apex += q.sqrt_j2() < 1e-9 * kC;
      REQUIRE(std::isfinite(q.stress(0)));
    }
    std::printf(
        "DP random 3D path (phi %.0f, psi %.0f, 3000 steps, spin included): max f/scale "
        "%.2e, %d steps ended at the apex\n",
        phi, psi, worst, apex);
    CHECK(worst <= 1e-10);
    if (phi > 0) CHECK(apex > 0);  // the path did visit the apex
  }
}

TEST_CASE("drucker_prager: the tension cutoff caps the mean stress",
          "[material][unit][drucker_prager]") {
  // T = 2 kPa below the apex (xi c / eta = 17.3 kPa): isotropic extension stops at p = T with no
  // deviator (the cap alone), and a stretch with shear ends on the corner p = T,
  // sqrt(J2) = xi c - eta T.
  Point iso(kC, kPhi, kPsi, ", tension_cutoff: 2000");
  iso.isotropic(0);
  for (int i = 0; i < 20; ++i) iso.step({1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3});
  Point corner(kC, kPhi, kPsi, ", tension_cutoff: 2000");
  corner.isotropic(0);
  for (int i = 0; i < 50; ++i) corner.step({1e-3, 2e-3, 0, 2e-3, 1e-3, 0, 0, 0, 1e-3});
  const double q_corner = corner.xi * kC - corner.eta * 2000;
  std::printf(
      "DP tension cutoff 2000 Pa: isotropic p %.6f Pa; corner p %.6f Pa, sqrt(J2) %.6f "
      "Pa against %.6f Pa\n",
      iso.mean(), corner.mean(), corner.sqrt_j2(), q_corner);
  CHECK(iso.mean() == Approx(2000).epsilon(1e-10));
  CHECK(iso.sqrt_j2() == Approx(0).margin(1e-6));
  CHECK(corner.mean() == Approx(2000).epsilon(1e-10));
  CHECK(corner.sqrt_j2() == Approx(q_corner).epsilon(1e-10));
}

TEST_CASE("drucker_prager: response is independent of the strain increment size",
          "[material][unit][drucker_prager]") {
  // Radial return is exact for a straight strain path from a state on the cone: the same total
  // strain in 1, 10 and 1000 increments ends at the same stress (tolerance 1e-9 relative).
  auto run = [](int n) {
    Point pt;
    pt.isotropic(-100e3);
    for (int i = 0; i < n; ++i) pt.compress_at_lateral_stress(0.002 / n, 100e3, kNu);
    return std::pair{pt.stress(0), pt.eqps()};
  };
  const auto [s1, e1] = run(1000);
  for (int n : {10, 100}) {
    const auto [s, e] = run(n);
    std::printf("DP increments %d: sigma_xx %.9f Pa (1000: %.9f), eq %.9e (1000: %.9e)\n", n, s, s1,
                e, e1);
    CHECK(s == Approx(s1).epsilon(1e-9));
    CHECK(e == Approx(e1).epsilon(1e-6));
  }
}

TEST_CASE("drucker_prager: a rigid rotation of a stressed point keeps its invariants",
          "[material][unit][drucker_prager]") {
  Point pt;
  pt.isotropic(-50e3);
  pt.stress(0) = -80e3, pt.stress(3) = 5e3;  // inside the cone
  const double p0 = pt.mean(), q0 = pt.sqrt_j2();
  // A spin w per step, n = 1000 steps (about a sixth of a turn): the trace is kept exactly; the
  // explicit Jaumann update grows the deviator by O(w^2) per step, n w^2 = 1e-3 in all
  // (tolerance 2 n w^2); the point stays inside the cone, so no plastic strain.
  const int n = 1000;
  const double w = 1e-3;
  for (int i = 0; i < n; ++i) pt.step({0, -w, 0, w, 0, 0, 0, 0, 0});
  std::printf(
      "DP rigid rotation: p %.9f -> %.9f Pa, sqrt(J2) %.9f -> %.9f Pa (%.2e, bound "
      "%.2e), eq %.2e\n",
      p0, pt.mean(), q0, pt.sqrt_j2(), pt.sqrt_j2() / q0 - 1, 2 * n * w * w, pt.eqps());
  CHECK(pt.mean() == Approx(p0).epsilon(1e-12));
  CHECK(std::fabs(pt.sqrt_j2() / q0 - 1) <= 2 * n * w * w);
  CHECK(pt.eqps() == 0);
}

TEST_CASE("drucker_prager: bad parameters give the located error",
          "[material][unit][drucker_prager]") {
  loam_test::check_bad_material(
      "type: drucker_prager, E: 1.0e7, nu: 0.3, density: 2000",
      {{", c: 0, phi: 30, psi: 40",
        ":7:92: error: bodies.0.material.psi: dilation angle psi = 40 "
        "must not exceed the friction angle phi = 30"},
       {", c: -1, phi: 30, psi: 0",
        ":7:75: error: bodies.0.material.c: -1 is out of range [0, inf) Pa"},
       {", c: 0, phi: 90, psi: 0",
        ":7:83: error: bodies.0.material.phi: 90 is out of range [0, 90) deg"},
       {", c: 0, phi: 30, psi: 0, match: triaxial",
        ":7:102: error: bodies.0.material.match: unknown value 'triaxial'; valid values are: "
        "compression, extension, plane_strain"}});
}

TEST_CASE("drucker_prager through loam element-test: the drained triaxial of its example config",
          "[material][element_test][drucker_prager]") {
  // configs/element_tests/drucker_prager_triaxial.yaml's material and path through the driver
  // (app/element_test.hpp): c = 0, phi = 30, psi = 10, p'0 = 100 kPa, 200 increments to
  // 5 %. Peak q = 200 kPa (Mohr-Coulomb's, compression cone) and the dilation at failure
  // d eps_v / d eps_a = -2 sin psi / (1 - sin psi) = -0.4202766 over the last increment, both to
  // 1e-6 (the driver holds the lateral stress to 1e-10 p'0).
  loam::ElementTest t;
  t.path = "triaxial_drained";
  t.confining = 100e3;
  t.strain = 0.05;
  t.increments = 200;
  const auto r = loam::run_element_test(
      "{type: drucker_prager, E: 20.0e6, nu: 0.3, density: 2000, c: 0, phi: 30, psi: 10}", t);
  REQUIRE(r.failure.empty());
  double peak = 0;
  for (size_t i = 0; i < r.rows.size(); ++i) peak = std::max(peak, r.at(long(i), "q"));
  const double dv = r.at(-1, "eps_v") - r.at(-2, "eps_v"),
               da = r.at(-1, "eps_a") - r.at(-2, "eps_a");
  const double sp = std::sin(rad(10)), dil = -2 * sp / (1 - sp);
  std::printf("DP element-test triaxial: peak q %.6f Pa (200000), dilation %.9f (%.9f)\n", peak,
              dv / da, dil);
  CHECK(peak == Approx(200e3).epsilon(1e-6));
  CHECK(dv / da == Approx(dil).epsilon(1e-6));
}

TEST_CASE(
    "drucker_prager: plane_strain matching gives Mohr-Coulomb's simple-shear strength at "
    "psi = 0",
    "[material][unit][drucker_prager]") {
  // Reference: the plane-strain limit state (materials/drucker_prager.cpp header): with the cone
  // matched for the given psi, f = 0 at zero out-of-plane plastic strain rate is Mohr-Coulomb's
  // t = c cos phi - s_m sin phi. Simple shear (L_xy only, plane strain) from an isotropic 100
  // kPa, c = 0, phi = 30 deg, to gamma = 0.1: the ratio tau_xy / -sigma_yy of drucker_prager
  // must equal mohr_coulomb's within 1e-3 (tending to sin phi = 0.5, Davis 1968). The cone
  // matched as if associated gave 0.4799. With psi > 0 this isochoric path has no limit state
  // (the dilation keeps raising the mean stress), so it cannot check those.
  for (double psi : {0.0}) {
    const std::string params = ", nu: " + std::to_string(kNu) +
                               ", density: 2000, c: 0, phi: 30, psi: " + std::to_string(psi);
    loam_test::MaterialPoint<3> dp("{type: drucker_prager, E: " + std::to_string(kE) + params +
                                   ", match: plane_strain}");
    loam_test::MaterialPoint<3> mc("{type: mohr_coulomb, E: " + std::to_string(kE) + params + "}");
    for (auto* pt : {&dp, &mc}) {
      pt->isotropic(-100e3);
      for (int i = 0; i < 1000; ++i) pt->step({0, 1e-4, 0, 0, 0, 0, 0, 0, 0});
    }
    const double r_dp = dp.stress(3) / -dp.stress(1), r_mc = mc.stress(3) / -mc.stress(1);
    std::printf(
        "simple shear phi 30 psi %.0f: tau/sigma_n drucker_prager plane_strain %.5f, "
        "mohr_coulomb %.5f\n",
        psi, r_dp, r_mc);
    CHECK(std::fabs(r_dp / r_mc - 1) <= 1e-3);
  }
}
