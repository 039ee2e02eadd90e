// Unit tests of the strain_softening_mc material at one material point (docs/verification.md
// section B), driven directly through MaterialBatch, and its parameter checks through the
// command line. Formulas here use compression positive (sigma'_1 >= sigma'_3), the material
// tension positive.
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

#include "cli.hpp"
#include "app/element_test.hpp"
#include "framework/tensor.hpp"
#include "material_point.hpp"

namespace {

constexpr double kE = 20e6, kNu = 0.3;

/// Softening parameters (angles in degrees).
struct Soft {
  double c_p = 10e3, c_r = 2e3, phi_p = 35, phi_r = 25, psi_p = 10, psi_r = 0;
  double start = 0.01, end = 0.05;
  std::string extra;  // further YAML, e.g. ", tension_cutoff: 2000"

  /// Parameters at equivalent plastic strain x (linear between start and end).
  double t(double x) const { return std::clamp((x - start) / (end - start), 0.0, 1.0); }
  double c(double x) const { return c_p + t(x) * (c_r - c_p); }
  double phi(double x) const { return phi_p + t(x) * (phi_r - phi_p); }

  std::string yaml() const {
    char m[512];
    std::snprintf(m, sizeof m,
                  "{type: strain_softening_mc, E: %g, nu: %g, density: 2000, c_peak: %.17g, "
                  "c_residual: %.17g, phi_peak: %.17g, phi_residual: %.17g, psi_peak: %.17g, "
                  "psi_residual: %.17g, softening_start: %.17g, softening_end: %.17g%s}",
                  kE, kNu, c_p, c_r, phi_p, phi_r, psi_p, psi_r, start, end, extra.c_str());
    return m;
  }
};

double rad(double deg) {
  return deg * M_PI / 180;
}

/// One material point of the first particle of any material with a plastic_strain_eq field,
/// strain-driven with L = strain increment (dt = 1).
template <int D>
struct Point : loam_test::MaterialPoint<D> {
  int eq = this->sim->sets[0].particles.find("plastic_strain_eq");

  explicit Point(const std::string& material) : loam_test::MaterialPoint<D>(material) {
    REQUIRE(eq >= 0);
  }
  double& eqps() { return this->field(eq); }
  /// Mohr-Coulomb yield value with cohesion c and friction angle phi, and a stress scale.
  std::pair<double, double> yield(double c, double phi) {
    const Eigen::Vector3d ev = this->principal_stress();
    const double s1 = ev[2], s3 = ev[0];
    const double sp = std::sin(rad(phi)), cp = std::cos(rad(phi));
    return {(s1 - s3) + (s1 + s3) * sp - 2 * c * cp, 2 * c * cp + ev.cwiseAbs().maxCoeff()};
  }
  /// Yield value with the parameters at the current plastic strain.
  std::pair<double, double> yield(const Soft& m) { return yield(m.c(eqps()), m.phi(eqps())); }
};

struct Row {
  double eps_a, sigma_1, eq, worst_f;
};

/// Drained compression along x at constant lateral stress -s3 (sigma_yy, in 3D also sigma_zz;
/// 2D plane strain), to axial strain `strain` in n increments. The lateral strain of each step
/// is found by a secant iteration so that sigma_yy = -s3 to 1e-10 s3. One row per increment.
template <int D>
std::vector<Row> drained_compression(Point<D>& pt, const Soft& m, double s3, double strain, int n) {
  std::vector<Row> rows;
  pt.isotropic(-s3);
  pt.eqps() = 0;
  const double da = strain / n;
  for (int i = 0; i < n; ++i) {
    pt.compress_at_lateral_stress(da, s3, kNu);
    auto [f, scale] = pt.yield(m);
    rows.push_back({da * (i + 1), -pt.stress(0), pt.eqps(), f / scale});
  }
  return rows;
}

double mc_peak(double s3, double c, double phi) {
  const double sp = std::sin(rad(phi)), cp = std::cos(rad(phi));
  return s3 * (1 + sp) / (1 - sp) + 2 * c * cp / (1 - sp);
}

/// sigma_1 of the rows interpolated linearly at axial strain e.
double sigma1_at(const std::vector<Row>& rows, double e) {
  if (e <= rows.front().eps_a) return rows.front().sigma_1;
  for (size_t i = 1; i < rows.size(); ++i)
    if (rows[i].eps_a >= e) {
      const double t = (e - rows[i - 1].eps_a) / (rows[i].eps_a - rows[i - 1].eps_a);
      return rows[i - 1].sigma_1 + t * (rows[i].sigma_1 - rows[i - 1].sigma_1);
    }
  return rows.back().sigma_1;
}

}  // namespace

TEST_CASE("strain_softening_mc: drained triaxial shows the peak then the residual strength",
          "[material][unit]") {
  // Reference: sigma_1,f = sigma_3 (1 + sin phi)/(1 - sin phi) + 2 c cos phi/(1 - sin phi),
  // with the peak parameters at the peak and the residual ones once plastic_strain_eq >=
  // softening_end. Tolerance 0.5% (docs/verification.md B); the return is exact, so round-off is
  // expected. softening_start 0.01 (a peak plateau) and 0 (the default: peak at first yield).
  for (double start : {0.01, 0.0}) {
    Soft m;
    m.start = start;
    Point<3> pt(m.yaml());
    const double s3 = 100e3;
    const auto rows = drained_compression(pt, m, s3, 0.15, 1500);
    double peak = 0, worst_f = 0, worst_res = 0;
    int residual_rows = 0;
    const double peak_exact = mc_peak(s3, m.c_p, m.phi_p);
    const double res_exact = mc_peak(s3, m.c_r, m.phi_r);
    for (const Row& r : rows) {
      peak = std::max(peak, r.sigma_1);
      worst_f = std::max(worst_f, r.worst_f);
      if (r.eq >= m.end) {
        ++residual_rows;
        worst_res = std::max(worst_res, std::fabs(r.sigma_1 - res_exact) / res_exact);
      }
    }
    std::printf(
        "SSMC triaxial (softening_start %.2f): peak sigma1 %.6f Pa, exact %.6f Pa, rel err "
        "%.2e; residual sigma1 %.6f Pa, exact %.6f Pa, max rel err over %d rows with eq >= "
        "softening_end %.2e; max f(current c, phi)/scale %.2e; final eq %.4f\n",
        start, peak, peak_exact, std::fabs(peak - peak_exact) / peak_exact, rows.back().sigma_1,
        res_exact, residual_rows, worst_res, worst_f, rows.back().eq);
    CHECK(std::fabs(peak - peak_exact) <= 0.005 * peak_exact);
    if (start > 0) CHECK(std::fabs(peak - peak_exact) <= 1e-8 * peak_exact);
    CHECK(residual_rows > 100);
    CHECK(worst_res <= 0.005);
    CHECK(worst_res <= 1e-8);  // exact return on the residual surface: round-off only
    CHECK(worst_f <= 1e-8);
    // Softening in between: sigma_1 decreases monotonically from the peak to the residual.
    bool monotone = true;
    for (size_t i = 1; i < rows.size(); ++i)
      if (rows[i - 1].eq > start && rows[i].sigma_1 > rows[i - 1].sigma_1 + 1e-6) monotone = false;
    CHECK(monotone);
  }
}

TEST_CASE("strain_softening_mc: element-test driver triaxial peak and residual",
          "[material][unit]") {
  // The same check through loam::run_element_test (triaxial_drained, sigma'_3 = 200 kPa, 15%
  // axial strain in 1500 increments): sigma'_1 = q + sigma'_3 peaks at the MC formula with the
  // peak parameters and ends at the one with the residual parameters, within 0.5%
  // (docs/verification.md B; round-off expected).
  Soft m;
  loam::ElementTest t;
  t.path = "triaxial_drained";
  t.confining = 200e3;
  t.strain = 0.15;
  t.increments = 1500;
  const auto r = loam::run_element_test(m.yaml(), t);
  REQUIRE(r.failure.empty());
  double peak = 0;
  for (size_t i = 0; i < r.rows.size(); ++i) peak = std::max(peak, r.at(long(i), "q"));
  peak += t.confining;
  const double res = r.at(-1, "q") + t.confining, eq = r.at(-1, "plastic_strain_eq");
  const double pe = mc_peak(t.confining, m.c_p, m.phi_p), re = mc_peak(t.confining, m.c_r, m.phi_r);
  std::printf(
      "SSMC element test (sigma3 200 kPa): peak sigma1 %.6f Pa, exact %.6f Pa (rel %.2e); final "
      "sigma1 %.6f Pa at eq %.4f, residual exact %.6f Pa (rel %.2e)\n",
      peak, pe, std::fabs(peak - pe) / pe, res, eq, re, std::fabs(res - re) / re);
  CHECK(std::fabs(peak - pe) <= 0.005 * pe);
  CHECK(eq > m.end);
  CHECK(std::fabs(res - re) <= 0.005 * re);
}

TEST_CASE("strain_softening_mc: plane strain softening stays on the current yield surface",
          "[material][unit]") {
  // Plane strain biaxial compression: the stress stays on the surface of the parameters at
  // the current plastic strain (f/scale <= 1e-8) and ends on the residual MC strength.
  Soft m;
  Point<2> pt(m.yaml());
  const auto rows = drained_compression(pt, m, 100e3, 0.15, 1500);
  double worst_f = 0;
  for (const Row& r : rows) worst_f = std::max(worst_f, r.worst_f);
  const double exact = mc_peak(100e3, m.c_r, m.phi_r);
  std::printf(
      "SSMC plane strain: final sigma1 %.6f Pa, residual exact %.6f Pa (rel %.2e), final eq "
      "%.4f; max f/scale %.2e\n",
      rows.back().sigma_1, exact, std::fabs(rows.back().sigma_1 - exact) / exact, rows.back().eq,
      worst_f);
  CHECK(rows.back().eq > m.end);
  CHECK(std::fabs(rows.back().sigma_1 - exact) <= 1e-8 * exact);
  CHECK(worst_f <= 1e-8);
}

TEST_CASE("strain_softening_mc: yield function with the current parameters after every return",
          "[material][unit]") {
  // Random 3D strain path with spin, mean drift to compression: after every step the stress is
  // admissible for c, phi at the new plastic_strain_eq. Also with a tension cutoff (Rankine
  // corner returns) and with associated flow.
  for (const std::string extra : {"", ", tension_cutoff: 1000"}) {
    for (double psi : {10.0, 35.0}) {
      Soft m;
      m.extra = extra;
      m.psi_p = psi;
      m.psi_r = std::min(psi, m.phi_r);
      m.end = 0.2;
      Point<3> q(m.yaml());
      q.isotropic(-100e3);
      std::mt19937 rng(11);
      std::normal_distribution<double> g(0.0, 1.0);
      double worst = 0, worst_t = 0;
      for (int i = 0; i < 2000; ++i) {
        std::vector<double> de(9);
        for (auto& x : de) x = 1e-3 * g(rng);
        de[0] -= 2e-4;
        q.step(de);
        auto [f, scale] = q.yield(m);
        worst = std::max(worst, f / scale);
        if (!extra.empty()) worst_t = std::max(worst_t, (q.principal_stress()[2] - 1000) / scale);
        REQUIRE(std::isfinite(q.stress(0)));
      }
      std::printf(
          "SSMC random 3D path (psi_peak %.0f%s): max f(current)/scale %.2e, max (s1 - T)/scale "
          "%.2e, eq plastic strain %.4f (softening range %.2f..%.2f)\n",
          psi, extra.c_str(), worst, worst_t, q.eqps(), m.start, m.end);
      CHECK(worst <= 1e-8);
      CHECK(worst_t <= 1e-8);
      CHECK(q.eqps() > m.start);
    }
  }
}

TEST_CASE("strain_softening_mc: response converges with the strain increment size",
          "[material][unit]") {
  // Drained triaxial curve sigma_1(eps_a) to 15% axial strain in 100, 1000 and 10000
  // increments, compared at 100 axial strains. Inside the softening branch the implicit
  // (end-of-step) strength makes the update first order in the increment, so the difference
  // to the 10000-increment curve must fall about 10x per 10x increments; tolerance: 100
  // increments within 1% of sigma_3 (0.4% of the peak), 1000 within 0.1%.
  Soft m;
  std::vector<std::vector<Row>> runs;
  for (int n : {100, 1000, 10000}) {
    Point<3> pt(m.yaml());
    runs.push_back(drained_compression(pt, m, 100e3, 0.15, n));
  }
  double diff[2] = {0, 0};
  for (int k = 0; k < 2; ++k)
    for (int i = 1; i <= 100; ++i) {
      const double e = 0.15 * i / 100;
      diff[k] = std::max(diff[k], std::fabs(sigma1_at(runs[size_t(k)], e) - sigma1_at(runs[2], e)));
    }
  const double eq_diff = std::fabs(runs[0].back().eq - runs[2].back().eq);
  std::printf(
      "SSMC triaxial increment size: max |sigma1(n) - sigma1(10000)| / sigma3: n = 100 %.2e, "
      "n = 1000 %.2e (ratio %.1f); final sigma1 100 vs 10000: %.3e Pa; final eq diff %.2e\n",
      diff[0] / 100e3, diff[1] / 100e3, diff[0] / diff[1],
      std::fabs(runs[0].back().sigma_1 - runs[2].back().sigma_1), eq_diff);
  CHECK(diff[0] <= 0.01 * 100e3);
  CHECK(diff[1] <= 0.001 * 100e3);
  CHECK(diff[0] / diff[1] > 5);
  CHECK(std::fabs(runs[0].back().sigma_1 - runs[2].back().sigma_1) <= 1e-8 * 100e3);
}

TEST_CASE("strain_softening_mc: with peak equal to residual it is mohr_coulomb exactly",
          "[material][unit]") {
  // Same random 3D path (with spin) on mohr_coulomb and on strain_softening_mc with
  // peak == residual: identical stress and plastic strain, bit for bit (same return code).
  for (const std::string extra : {"", ", tension_cutoff: 1500"}) {
    Soft m;
    m.c_r = m.c_p, m.phi_r = m.phi_p, m.psi_r = m.psi_p, m.extra = extra;
    char mc[256];
    std::snprintf(mc, sizeof mc,
                  "{type: mohr_coulomb, E: %g, nu: %g, density: 2000, c: %g, phi: %g, psi: %g%s}",
                  kE, kNu, m.c_p, m.phi_p, m.psi_p, extra.c_str());
    Point<3> a(m.yaml()), b(mc);
    a.isotropic(-100e3), b.isotropic(-100e3);
    std::mt19937 rng(5);
    std::normal_distribution<double> g(0.0, 1.0);
    double worst = 0;
    for (int i = 0; i < 3000; ++i) {
      std::vector<double> de(9);
      for (auto& x : de) x = 1e-3 * g(rng);
      de[0] -= 1e-4;
      a.step(de), b.step(de);
      for (int k = 0; k < 6; ++k) worst = std::max(worst, std::fabs(a.stress(k) - b.stress(k)));
      worst = std::max(worst, std::fabs(a.eqps() - b.eqps()) * kE);
    }
    std::printf(
        "SSMC peak == residual vs mohr_coulomb%s, 3000 random steps: max |stress diff| (and "
        "E |eq diff|) %.3e Pa; eq %.6f vs %.6f\n",
        extra.c_str(), worst, a.eqps(), b.eqps());
    CHECK(worst == 0.0);
    CHECK(a.eqps() > 0);
  }
}

TEST_CASE("strain_softening_mc: a rigid rotation of a softening point keeps its invariants",
          "[material][unit]") {
  // Jaumann objectivity: load a plane strain point into the middle of the softening range,
  // then spin it by 90 degrees in 1000 steps (no strain). The mean stress, q and the plastic
  // strain keep their values (tolerance 5e-3 relative for the stress: the explicit Jaumann
  // increment grows the stress by O((w dt)^2) per step; the plastic strain may then grow only
  // by the matching return, bounded here by 1e-4), the point stays on the current surface and
  // its principal axes swap.
  Soft m;
  Point<2> pt(m.yaml());
  const auto rows = drained_compression(pt, m, 100e3, 0.045, 450);
  const double eq0 = pt.eqps();
  REQUIRE(eq0 > m.start);
  REQUIRE(eq0 < m.end);
  auto invariants = [&](double& mean, double& q) {
    mean = (pt.stress(0) + pt.stress(1) + pt.stress(2)) / 3;
    const double dx = pt.stress(0) - mean, dy = pt.stress(1) - mean, dz = pt.stress(2) - mean;
    q = std::sqrt(1.5 * (dx * dx + dy * dy + dz * dz + 2 * pt.stress(3) * pt.stress(3)));
  };
  double mean0, q0, mean1, q1;
  invariants(mean0, q0);
  const double sxx0 = pt.stress(0), syy0 = pt.stress(1);
  const int steps = 1000;
  const double w = M_PI / 2 / steps;
  double worst = 0;
  for (int i = 0; i < steps; ++i) {
    pt.step({0, -w, w, 0});
    auto [f, scale] = pt.yield(m);
    worst = std::max(worst, f / scale);
  }
  invariants(mean1, q1);
  std::printf(
      "SSMC rotated 90 deg: mean %.3f -> %.3f Pa (rel %.2e), q %.3f -> %.3f Pa (rel %.2e), eq "
      "%.6f -> %.6f; xx %.3f (was yy %.3f), yy %.3f (was xx %.3f); max f/scale %.2e\n",
      mean0, mean1, std::fabs(mean1 - mean0) / std::fabs(mean0), q0, q1, std::fabs(q1 - q0) / q0,
      eq0, pt.eqps(), pt.stress(0), syy0, pt.stress(1), sxx0, worst);
  CHECK(std::fabs(mean1 - mean0) <= 5e-3 * std::fabs(mean0));
  CHECK(std::fabs(q1 - q0) <= 5e-3 * q0);
  CHECK(pt.eqps() - eq0 <= 1e-4);
  CHECK(pt.stress(0) == Approx(syy0).epsilon(5e-3));
  CHECK(pt.stress(1) == Approx(sxx0).epsilon(5e-3));
  CHECK(worst <= 1e-8);
}

TEST_CASE("strain_softening_mc: bad parameters give the located error", "[material][unit]") {
  // Columns point at the offending value on line 7.
  const std::vector<loam_test::BadMaterial> cases = {
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 2000, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1",
       ":7:103: error: bodies.0.material.c_residual: residual c_residual = 2000 must not exceed "
       "the peak c_peak = 1000 (softening only)"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 32, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1",
       ":7:134: error: bodies.0.material.phi_residual: residual phi_residual = 32 must not "
       "exceed the peak phi_peak = 30 (softening only)"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 6, softening_end: 0.1",
       ":7:165: error: bodies.0.material.psi_residual: residual psi_residual = 6 must not "
       "exceed the peak psi_peak = 5 (softening only)"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 31, psi_residual: 0, softening_end: 0.1",
       ":7:148: error: bodies.0.material.psi_peak: dilation angle psi_peak = 31 must not exceed "
       "the friction angle phi_peak = 30"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 25, psi_residual: 21, softening_end: 0.1",
       ":7:166: error: bodies.0.material.psi_residual: dilation angle psi_residual = 21 must not "
       "exceed the friction angle phi_residual = 20"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_start: 0.1, softening_end: 0.1",
       ":7:205: error: bodies.0.material.softening_end: softening_end = 0.1 must exceed "
       "softening_start = 0.1"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 90, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1",
       ":7:116: error: bodies.0.material.phi_peak: 90 is out of range [0, 90) deg"},
      {"E: 1.0e6, nu: 0.5, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1",
       ":7:72: error: bodies.0.material.nu: 0.5 is out of range [0, 0.5)"},
      {"E: 1.0e6, nu: 0.3, c_peak: -1, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1",
       ":7:85: error: bodies.0.material.c_peak: -1 is out of range [0, inf) Pa"},
      {"E: 0, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1",
       ":7:61: error: bodies.0.material.E: 0 is out of range (0, inf) Pa"},
      {"E: 1.0e6, nu: 0.3, c_peak: 1000, c_residual: 0, phi_peak: 30, phi_residual: 20, "
       "psi_peak: 5, psi_residual: 0, softening_end: 0.1, characteristic_length: -1",
       ":7:211: error: bodies.0.material.characteristic_length: -1 is out of range (0, inf) m"},
  };
  loam_test::check_bad_material("type: strain_softening_mc, density: 2000, ", cases);
}

TEST_CASE("strain_softening_mc: characteristic_length scales the softening strains by l_c / h",
          "[material][unit][regularisation]") {
  // Regularisation: with characteristic_length l_c the softening strains apply to a band l_c
  // wide and are scaled by l_c / h, h the grid's cell size, the narrowest band it resolves
  // (here the one-point config's 0.25 m cells, 2 points per cell).
  //  - l_c = h: scale 1, bitwise the unregularised response;
  //  - l_c = 2 h: bitwise the response with softening_start and softening_end doubled
  //    (0.01 -> 0.02, 0.05 -> 0.10: the products are exact in binary).
  // Plane strain drained compression at 100 kPa to 15 % axial strain, 1500 increments.
  auto run = [](const Soft& m) {
    Point<2> pt(m.yaml());
    return drained_compression(pt, m, 100e3, 0.15, 1500);
  };
  Soft plain;
  Soft same = plain;
  same.extra = ", characteristic_length: 0.25";
  Soft twice = plain;
  twice.extra = ", characteristic_length: 0.5";
  Soft stretched = plain;
  stretched.start = 0.02;
  stretched.end = 0.10;
  const auto a = run(plain), b = run(same), c = run(twice), d = run(stretched);
  REQUIRE(a.size() == b.size());
  REQUIRE(c.size() == d.size());
  bool ab = true, cd = true, ac = true;
  double eq_a = NAN, eq_c = NAN;  // the plastic strain where each first reaches residual
  for (size_t i = 0; i < a.size(); ++i) {
    ab = ab && a[i].sigma_1 == b[i].sigma_1 && a[i].eq == b[i].eq;
    cd = cd && c[i].sigma_1 == d[i].sigma_1 && c[i].eq == d[i].eq;
    ac = ac && a[i].sigma_1 == c[i].sigma_1;
    if (std::isnan(eq_a) && a[i].eq >= plain.end) eq_a = a[i].eq;
    if (std::isnan(eq_c) && c[i].eq >= stretched.end) eq_c = c[i].eq;
  }
  std::printf(
      "characteristic_length: l_c = h bitwise the plain response: %s; l_c = 2 h "
      "bitwise softening strains x 2: %s; residual reached at eq %.4f (plain) and %.4f "
      "(l_c = 2 h)\n",
      ab ? "yes" : "no", cd ? "yes" : "no", eq_a, eq_c);
  CHECK(ab);
  CHECK(cd);
  CHECK_FALSE(ac);  // the scaling acts
  CHECK(eq_c / eq_a == Approx(2).epsilon(0.05));
}
