// Unit tests of the mohr_coulomb material at one material point (docs/verification.md section B),
// driven directly through MaterialBatch, and its parameter checks through the command line.
// Formulas here use compression positive (sigma'_1 >= sigma'_3), the material tension positive.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "cli.hpp"
#include "framework/tensor.hpp"
#include "material_point.hpp"

namespace {

constexpr double kE = 20e6, kNu = 0.3, kC = 10e3, kPhi = 30, kPsi = 10;

std::string mc(double c = kC, double phi = kPhi, double psi = kPsi, const std::string& extra = "") {
  char mat[256];
  std::snprintf(mat, sizeof mat,
                "{type: mohr_coulomb, E: %g, nu: %g, density: 2000, c: %g, phi: %g, psi: %g%s}", kE,
                kNu, c, phi, psi, extra.c_str());
  return mat;
}

double rad(double deg) {
  return deg * M_PI / 180;
}

/// One material point of the first particle, strain-driven with L = diag/offdiag increments.
template <int D>
struct Point : loam_test::MaterialPoint<D> {
  double phi, psi, c;
  int eq = this->handle("plastic_strain_eq");

  explicit Point(double c_ = kC, double phi_ = kPhi, double psi_ = kPsi,
                 const std::string& extra = "")
      : loam_test::MaterialPoint<D>(mc(c_, phi_, psi_, extra)), phi(phi_), psi(psi_), c(c_) {}
  double& eqps() { return this->field(eq); }
  /// Mohr-Coulomb yield value (tension positive) and a stress scale.
  std::pair<double, double> yield() {
    const Eigen::Vector3d ev = this->principal_stress();
    const double s1 = ev[2], s3 = ev[0];
    const double sp = std::sin(rad(phi)), cp = std::cos(rad(phi));
    return {(s1 - s3) + (s1 + s3) * sp - 2 * c * cp, 2 * c * cp + ev.cwiseAbs().maxCoeff()};
  }
};

struct PathResult {
  double peak = 0;      // largest axial stress (compression positive)
  double ratio = 0;     // d eps_v / d eps_1 over the last increment (compression positive)
  double ps_ratio = 0;  // -d eps_v / d (eps_1 - eps_3) over the last increment
  double worst_f = 0;   // largest f / scale after any return
  std::vector<double> final_stress;
  double final_eq = 0;
};

/// Drained compression along x at constant lateral stress -s3 (sigma_yy and, in 3D, sigma_zz);
/// in 2D the z strain is zero (plane strain). The lateral strain increment of each step is
/// found by a secant iteration so that sigma_yy = -s3 to round-off.
template <int D>
PathResult drained_compression(Point<D>& pt, double s3, double strain, int n) {
  PathResult r;
  pt.isotropic(-s3);
  pt.eqps() = 0;
  const double da = strain / n;
  double last_dv = 0, last_d1 = 0, last_d3 = 0;
  for (int i = 0; i < n; ++i) {
    const double e1 = pt.compress_at_lateral_stress(da, s3, kNu);
    r.peak = std::max(r.peak, -pt.stress(0));
    auto [f, scale] = pt.yield();
    r.worst_f = std::max(r.worst_f, f / scale);
    last_d1 = da;
    last_d3 = -e1;
    last_dv = da - (D - 1) * e1;
  }
  r.ratio = last_dv / last_d1;
  r.ps_ratio = -last_dv / (last_d1 - last_d3);
  for (int k = 0; k < Point<D>::NS; ++k) r.final_stress.push_back(pt.stress(k));
  r.final_eq = pt.eqps();
  return r;
}

double mc_peak(double s3, double c, double phi) {
  const double sp = std::sin(rad(phi)), cp = std::cos(rad(phi));
  return s3 * (1 + sp) / (1 - sp) + 2 * c * cp / (1 - sp);
}

}  // namespace

TEST_CASE("mohr_coulomb: drained triaxial peak matches the Mohr-Coulomb formula at 3 confinements",
          "[material][unit]") {
  for (double s3 : {50e3, 100e3, 200e3}) {
    Point<3> pt;
    const auto r = drained_compression(pt, s3, 0.05, 1000);
    const double exact = mc_peak(s3, kC, kPhi);
    std::printf(
        "MC triaxial 3D: sigma3 %.0f Pa: peak sigma1 %.6f Pa, exact %.6f Pa, rel err %.2e, "
        "max f/scale %.2e\n",
        s3, r.peak, exact, std::fabs(r.peak - exact) / exact, r.worst_f);
    CHECK(std::fabs(r.peak - exact) <= 0.005 * exact);
    CHECK(std::fabs(r.peak - exact) <= 1e-8 * exact);  // exact return: round-off only
    CHECK(r.worst_f <= 1e-8);
    CHECK(pt.eqps() > 0);
  }
}

TEST_CASE("mohr_coulomb: plane strain biaxial peak and dilation sin psi relation",
          "[material][unit]") {
  Point<2> pt;
  const double s3 = 100e3;
  const auto r = drained_compression(pt, s3, 0.05, 1000);
  const double exact = mc_peak(s3, kC, kPhi);
  std::printf(
      "MC plane strain: peak %.6f Pa exact %.6f Pa (rel %.2e); -dev/d(e1-e3) %.9f, "
      "sin psi %.9f; max f/scale %.2e\n",
      r.peak, exact, std::fabs(r.peak - exact) / exact, r.ps_ratio, std::sin(rad(kPsi)), r.worst_f);
  CHECK(std::fabs(r.peak - exact) <= 1e-8 * exact);
  CHECK(r.ps_ratio == Approx(std::sin(rad(kPsi))).epsilon(1e-6));
  CHECK(r.worst_f <= 1e-8);
  // sigma_zz stays intermediate: between the axial and the lateral stress.
  CHECK(pt.stress(2) < -s3);
  CHECK(pt.stress(2) > -exact);
}

TEST_CASE("mohr_coulomb: triaxial dilation rate at failure matches psi", "[material][unit]") {
  for (double psi : {0.0, 10.0, 30.0}) {
    Point<3> pt(kC, kPhi, psi);
    const auto r = drained_compression(pt, 100e3, 0.05, 1000);
    const double sp = std::sin(rad(psi)), exact = -2 * sp / (1 - sp);
    std::printf("MC triaxial dilation psi %.0f: d eps_v/d eps_1 %.9f, exact %.9f\n", psi, r.ratio,
                exact);
    CHECK(r.ratio == Approx(exact).margin(1e-6));
  }
}

TEST_CASE("mohr_coulomb: yield function is satisfied after every return on a random 3D path",
          "[material][unit]") {
  // Also Tresca (phi = psi = 0, no apex) and associated flow (psi = phi).
  for (auto [phi, psi] : {std::pair{30.0, 10.0}, std::pair{0.0, 0.0}, std::pair{45.0, 45.0}}) {
    Point<3> q(kC, phi, psi);
    q.isotropic(-100e3);
    std::mt19937 rng(11);
    std::normal_distribution<double> g(0.0, 1.0);
    double worst = 0;
    for (int i = 0; i < 2000; ++i) {
      std::vector<double> de(9);
      for (auto& x : de) x = 1e-3 * g(rng);
      de[0] -= 2e-4;  // mean drift to compression keeps the path away from the apex on average
      q.step(de);
      auto [f, scale] = q.yield();
      worst = std::max(worst, f / scale);
      REQUIRE(std::isfinite(q.stress(0)));
    }
    std::printf(
        "MC random 3D path (phi %.0f, psi %.0f, 2000 steps, spin included): max f/scale "
        "%.2e, eq plastic strain %.4f\n",
        phi, psi, worst, q.eqps());
    CHECK(worst <= 1e-8);
    CHECK(q.eqps() > 0);
  }
  Point<3> pt;
  // Apex and tension cutoff: pure isotropic extension ends at the apex c/tan(phi), or at T.
  pt.isotropic(0);
  for (int i = 0; i < 10; ++i) pt.step({1e-3, 0, 0, 0, 1e-3, 0, 0, 0, 1e-3});
  const double apex = kC / std::tan(rad(kPhi));
  std::printf("MC isotropic extension: stress %.6f Pa, apex %.6f Pa\n", pt.stress(0), apex);
  CHECK(pt.stress(0) == Approx(apex).epsilon(1e-10));
  CHECK(pt.stress(2) == Approx(apex).epsilon(1e-10));
}

TEST_CASE("mohr_coulomb: tension cutoff caps the largest principal stress", "[material][unit]") {
  Point<3> pt(kC, kPhi, kPsi, ", tension_cutoff: 2000");
  pt.isotropic(0);
  double worst = 0;
  for (int i = 0; i < 50; ++i) {
    pt.step({2e-4, 0, 0, 0, -5e-5, 0, 0, 0, 0});  // stretch x, squeeze y
    const double s1 = pt.principal_stress()[2];
    worst = std::max(worst, s1 - 2000);
    auto [f, scale] = pt.yield();
    worst = std::max(worst, f / scale * 1e3);
  }
  std::printf("MC tension cutoff 2000 Pa: sigma_xx %.6f Pa, max violation %.2e\n", pt.stress(0),
              worst);
  CHECK(pt.stress(0) == Approx(2000).epsilon(1e-9));
  CHECK(worst <= 1e-6);
}

TEST_CASE("mohr_coulomb: response is independent of the strain increment size",
          "[material][unit]") {
  Point<3> a, b;
  const auto ra = drained_compression(a, 100e3, 0.05, 100);
  const auto rb = drained_compression(b, 100e3, 0.05, 1000);
  double worst = 0;
  for (size_t k = 0; k < ra.final_stress.size(); ++k)
    worst = std::max(worst, std::fabs(ra.final_stress[k] - rb.final_stress[k]) / 100e3);
  std::printf(
      "MC 100 vs 1000 increments to 5%% axial strain: max stress difference / sigma3 "
      "%.2e; eq plastic strain %.9f vs %.9f\n",
      worst, ra.final_eq, rb.final_eq);
  CHECK(worst <= 1e-6);
  CHECK(ra.final_eq == Approx(rb.final_eq).epsilon(1e-6));

  // A proportional 3D path with shear (no spin) in 10 vs 1000 increments, ending on the main
  // plane or an edge, agrees within the same tolerance once the stress is stationary.
  Point<3> c1, c2;
  c1.isotropic(-100e3), c2.isotropic(-100e3);
  const std::vector<double> dir = {-1.0, 0.1, 0, 0.1, 0.3, 0.05, 0, 0.05, 0.2};
  auto scaled = [&](double f) {
    std::vector<double> v(dir);
    for (auto& x : v) x *= f;
    return v;
  };
  for (int i = 0; i < 10; ++i) c1.step(scaled(0.005));
  for (int i = 0; i < 1000; ++i) c2.step(scaled(0.00005));
  double worst2 = 0;
  for (int k = 0; k < 6; ++k)
    worst2 = std::max(worst2, std::fabs(c1.stress(k) - c2.stress(k)) / 100e3);
  std::printf(
      "MC proportional 3D path, 10 vs 1000 increments: max stress difference / 1e5 Pa "
      "%.2e\n",
      worst2);
  CHECK(worst2 <= 1e-6);
}

TEST_CASE("mohr_coulomb: 1D confined extension reaches the triaxial extension edge",
          "[material][unit]") {
  // Uniaxial strain from isotropic compression, stretching x: sigma_yy = sigma_zz, so the
  // plastic state is the s2 = s3 edge, where k sigma_xx - sigma_yy = sc exactly (tension
  // positive). (Confined compression with nu = 0.3 stays elastic: K0 = nu/(1-nu) > 1/k.)
  Point<1> pt;
  pt.isotropic(-200e3);
  double worst = 0;
  for (int i = 0; i < 100; ++i) {
    pt.step({1e-4});
    auto [f, scale] = pt.yield();
    worst = std::max(worst, f / scale);
  }
  const double sp = std::sin(rad(kPhi)), cp = std::cos(rad(kPhi));
  const double k = (1 + sp) / (1 - sp), sc = 2 * kC * cp / (1 - sp);
  std::printf(
      "MC 1D confined extension: sigma_xx %.3f sigma_yy %.3f sigma_zz %.3f Pa; "
      "k sxx - syy - sc = %.2e Pa; eq plastic strain %.6f; max f/scale %.2e\n",
      pt.stress(0), pt.stress(1), pt.stress(2), k * pt.stress(0) - pt.stress(1) - sc, pt.eqps(),
      worst);
  CHECK(pt.stress(1) == Approx(pt.stress(2)).epsilon(1e-12));
  CHECK(pt.stress(0) > pt.stress(1));
  CHECK(std::fabs(k * pt.stress(0) - pt.stress(1) - sc) <= 1e-9 * 200e3);
  CHECK(worst <= 1e-8);
  CHECK(pt.eqps() > 0);
}

TEST_CASE("mohr_coulomb: a rigid rotation of a stressed point keeps its invariants",
          "[material][unit]") {
  // Jaumann objectivity: a stress on the yield surface (plane strain), spun by 90 degrees in
  // 1000 steps, keeps its mean stress, stays admissible and swaps its principal axes.
  Point<2> pt;
  pt.stress(0) = -334641.016151377, pt.stress(1) = -100e3, pt.stress(2) = -200e3;
  pt.stress(3) = 0;
  auto [f0, scale0] = pt.yield();
  const int steps = 1000;
  const double w = M_PI / 2 / steps;
  double worst = 0;
  for (int i = 0; i < steps; ++i) {
    pt.step({0, -w, w, 0});
    auto [f, scale] = pt.yield();
    worst = std::max(worst, f / scale);
  }
  const double mean = (pt.stress(0) + pt.stress(1) + pt.stress(2)) / 3;
  std::printf(
      "MC rotated: f0/scale %.2e; xx %.3f yy %.3f zz %.3f xy %.3f Pa; mean %.6f "
      "(initial %.6f); max f/scale %.2e\n",
      f0 / scale0, pt.stress(0), pt.stress(1), pt.stress(2), pt.stress(3), mean,
      (-334641.016151377 - 300e3) / 3, worst);
  CHECK(std::fabs(f0 / scale0) < 1e-12);
  CHECK(worst <= 1e-8);
  CHECK(pt.stress(1) == Approx(-334641.016151377).epsilon(5e-3));
  CHECK(pt.stress(0) == Approx(-100e3).epsilon(5e-3));
  CHECK(mean == Approx((-334641.016151377 - 300e3) / 3).epsilon(5e-3));
}

TEST_CASE("mohr_coulomb: bad parameters give the located error", "[material][unit]") {
  const std::vector<loam_test::BadMaterial> cases = {
      {"nu: 0.3, c: 1000, phi: 30, psi: 35",
       ":7:93: error: bodies.0.material.psi: dilation angle psi = 35 must not exceed the "
       "friction angle phi = 30"},
      {"nu: 0.3, c: 1000, phi: 90, psi: 0",
       ":7:84: error: bodies.0.material.phi: 90 is out of range [0, 90) deg"},
      {"nu: 0.3, c: -1, phi: 30, psi: 0",
       ":7:73: error: bodies.0.material.c: -1 is out of range [0, inf) Pa"},
      // Soil models take nu in [0, 0.5): a negative Poisson's ratio is rejected.
      {"nu: -0.1, c: 1000, phi: 30, psi: 0",
       ":7:65: error: bodies.0.material.nu: -0.1 is out of range [0, 0.5)"},
      {"nu: 0.5, c: 1000, phi: 30, psi: 0",
       ":7:65: error: bodies.0.material.nu: 0.5 is out of range [0, 0.5)"},
  };
  loam_test::check_bad_material("type: mohr_coulomb, E: 1.0e6, density: 2000, ", cases);
}
