// Unit tests of the modified_cam_clay material (docs/verification.md section B): laboratory paths
// through the element-test driver (app/element_test.hpp), single material points in 1D,
// 2D and 3D driven directly through MaterialBatch, and the parameter checks through the command
// line. In the formulas p', q, strains and pc are compression positive (soil mechanics); the
// material itself stores tension-positive Cauchy stress.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>
#include <vector>

#include "cli.hpp"
#include "app/element_test.hpp"
#include "framework/tensor.hpp"
#include "material_point.hpp"

namespace {

constexpr double kLambda = 0.2, kKappa = 0.04, kM = 1.2, kNu = 0.3, kE0 = 1.0;
constexpr double kP0 = 100e3;  // Pa, initial mean effective stress of the element tests

/// The material as YAML; `extra` adds parameters (e.g. ", ocr: 4"); e0 and nu are added unless
/// `extra` gives v0 or G instead.
std::string mcc(const std::string& extra = ", ocr: 1") {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "{type: modified_cam_clay, lambda: %g, kappa: %g, M: %g, density: 1800%s", kLambda,
                kKappa, kM, extra.c_str());
  std::string s = buf;
  if (extra.find("v0:") == std::string::npos) s += ", e0: " + std::to_string(kE0);
  if (extra.find("G:") == std::string::npos) s += ", nu: " + std::to_string(kNu);
  return s + "}";
}

loam::ElementTest path(const std::string& name, double strain, int increments, double unload = 0) {
  loam::ElementTest t;
  t.path = name;
  t.confining = kP0;
  t.strain = strain;
  t.increments = increments;
  t.unload_strain = unload;
  return t;
}

loam::ElementTestResult run(const std::string& material, const loam::ElementTest& t) {
  auto r = loam::run_element_test(material, t);
  INFO(r.failure);
  REQUIRE(r.failure.empty());
  return r;
}

/// Largest f/pc^2 over the rows of an element test, f = q^2/M^2 + p'(p' - pc).
double worst_yield(const loam::ElementTestResult& r) {
  double worst = -1e300;
  const int cp = r.column("p"), cq = r.column("q"), cc = r.column("preconsolidation_pressure");
  for (const auto& row : r.rows) {
    const double p = row[size_t(cp)], q = row[size_t(cq)], pc = row[size_t(cc)];
    worst = std::max(worst, (q * q / (kM * kM) + p * (p - pc)) / (pc * pc));
  }
  return worst;
}

/// Least-squares slope of e against ln p' over rows [from, to].
double e_lnp_slope(const loam::ElementTestResult& r, size_t from, size_t to) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(to - from + 1);
  for (size_t i = from; i <= to; ++i) {
    const double x = std::log(r.at(long(i), "p")), y = r.at(long(i), "void_ratio");
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

/// One material point (the first particle) strain-driven through MaterialBatch with dt = 1.
template <int D>
struct Point : loam_test::MaterialPoint<D> {
  int e_field = this->handle("void_ratio"), pc_field = this->handle("preconsolidation_pressure");

  explicit Point(const std::string& material = mcc(", pc0: 100e3"))
      : loam_test::MaterialPoint<D>(material) {}
  double& pc() { return this->field(pc_field); }
  double& e() { return this->field(e_field); }
  /// Impose a stress (tension positive Voigt, NS components) and re-initialize the state.
  void set(const std::vector<double>& s) {
    for (int k = 0; k < Point::NS; ++k) this->stress(k) = s[size_t(k)];
    this->sim->materials[0]->initialize(this->sim->sets[0].particles, 0, 1);
  }
  double f_rel() {
    const double p = this->p(), q = this->q();
    return (q * q / (kM * kM) + p * (p - pc())) / (pc() * pc());
  }
};

}  // namespace

TEST_CASE("modified_cam_clay: drained triaxial from the NCL ends on the critical state line",
          "[material][unit]") {
  // Reference: docs/verification.md B (drained triaxial from an NC state ends on q/p' = M). At
  // constant confining stress dq = 3 dp', so the critical state is p'_cs = 3 p'0/(3 - M),
  // q_cs = M p'_cs, and (MCC: the CSL lies at pc = 2p' on the NCL) the void ratio there is
  // e_cs = e0 + lambda ln(p'0/p'_cs) - (lambda - kappa) ln 2. Tolerance 1% (the approach to
  // the critical state is asymptotic: q/p' is 1.2% below M at 50% axial strain, 0.1% at 80%).
  const auto r = run(mcc(), path("triaxial_drained", 0.8, 800));
  const double p = r.at(-1, "p"), q = r.at(-1, "q"), e = r.at(-1, "void_ratio");
  const double p_cs = 3 * kP0 / (3 - kM);
  const double e_cs = kE0 + kLambda * std::log(kP0 / p_cs) - (kLambda - kKappa) * std::log(2.0);
  double path_err = 0;  // drained triaxial stress path: q = 3 (p' - p'0)
  for (size_t i = 0; i < r.rows.size(); ++i)
    path_err = std::max(path_err, std::fabs(r.at(long(i), "q") - 3 * (r.at(long(i), "p") - kP0)));
  std::printf(
      "MCC drained triaxial NC (80%% axial, 800 increments): q/p' %.6f, M %.6f, rel err %.2e; "
      "p' %.1f Pa vs p'_cs %.1f (rel %.2e); e %.6f vs e_cs %.6f (abs %.2e); "
      "max |q - 3(p'-p'0)| %.2e Pa; max f/pc^2 %.2e\n",
      q / p, kM, std::fabs(q / p - kM) / kM, p, p_cs, std::fabs(p - p_cs) / p_cs, e, e_cs,
      std::fabs(e - e_cs), path_err, worst_yield(r));
  CHECK(std::fabs(q / p - kM) <= 0.01 * kM);
  CHECK(std::fabs(p - p_cs) <= 0.01 * p_cs);
  CHECK(std::fabs(e - e_cs) <= 0.01 * (1 + e_cs));
  CHECK(path_err <= 1e-6 * kP0);
  CHECK(worst_yield(r) <= 1e-9);
}

TEST_CASE("modified_cam_clay: heavily overconsolidated drained triaxial softens to the CSL",
          "[material][unit]") {
  // Dry side: OCR 10, peak above the CSL then dilation and softening down to q/p' = M at the
  // same p'_cs = 3 p'0/(3 - M) (docs/verification.md B critical state). Tolerance 1% at 80% axial
  // strain (2% above M at 40%).
  const auto r = run(mcc(", ocr: 10"), path("triaxial_drained", 0.8, 800));
  double peak = 0;
  for (size_t i = 0; i < r.rows.size(); ++i) peak = std::max(peak, r.at(long(i), "q"));
  const double p = r.at(-1, "p"), q = r.at(-1, "q");
  const double p_cs = 3 * kP0 / (3 - kM);
  std::printf(
      "MCC drained triaxial OCR 10 (80%% axial, 800 increments): pc0 %.0f Pa; peak q %.1f Pa, "
      "final q/p' %.6f (rel err "
      "%.2e), p' %.1f vs %.1f (rel %.2e); eps_v %.4f (dilation < 0); max f/pc^2 %.2e\n",
      r.at(0, "preconsolidation_pressure"), peak, q / p, std::fabs(q / p - kM) / kM, p, p_cs,
      std::fabs(p - p_cs) / p_cs, r.at(-1, "eps_v"), worst_yield(r));
  CHECK(r.at(0, "preconsolidation_pressure") == Approx(10 * kP0).epsilon(1e-12));
  CHECK(peak > 1.05 * q);
  CHECK(r.at(-1, "eps_v") < 0);
  CHECK(std::fabs(q / p - kM) <= 0.01 * kM);
  CHECK(std::fabs(p - p_cs) <= 0.01 * p_cs);
  CHECK(worst_yield(r) <= 1e-9);
}

TEST_CASE("modified_cam_clay: undrained triaxial from the NCL ends at the closed-form mean stress",
          "[material][unit]") {
  // Reference: docs/verification.md B. Undrained (v constant): the elastic volumetric strain
  // cancels the plastic one, so kappa ln(p'/p'0) = -(lambda - kappa) ln(pc/pc0) along the
  // whole path (exact for the e-ln p' laws). From the NCL (pc0 = p'0) to the critical state
  // (pc = 2p'): lambda ln(p'/p'0) = -(lambda - kappa) ln 2, i.e.
  //   p'_f = p'0 (1/2)^Lambda,  Lambda = (lambda - kappa)/lambda,  q_f = M p'_f.
  // Tolerance 1% at 40% axial strain; the path relation holds to round-off at every step.
  const auto r = run(mcc(), path("triaxial_undrained", 0.4, 800));
  const double Lam = (kLambda - kKappa) / kLambda;
  const double pf = kP0 * std::pow(0.5, Lam);
  const double p = r.at(-1, "p"), q = r.at(-1, "q");
  double rel_err = 0;
  for (size_t i = 0; i < r.rows.size(); ++i) {
    const double lhs = kKappa * std::log(r.at(long(i), "p") / kP0);
    const double rhs =
        -(kLambda - kKappa) * std::log(r.at(long(i), "preconsolidation_pressure") / kP0);
    rel_err = std::max(rel_err, std::fabs(lhs - rhs));
  }
  std::printf(
      "MCC undrained triaxial NC (40%% axial, 800 increments): p'_f %.3f Pa, closed form %.3f "
      "(rel err %.2e); q/p' %.6f vs M (rel %.2e); void ratio change %.2e; "
      "max |kappa ln(p'/p'0) + (lambda-kappa) ln(pc/pc0)| %.2e; max f/pc^2 %.2e\n",
      p, pf, std::fabs(p - pf) / pf, q / p, std::fabs(q / p - kM) / kM,
      std::fabs(r.at(-1, "void_ratio") - kE0), rel_err, worst_yield(r));
  CHECK(std::fabs(p - pf) <= 0.01 * pf);
  CHECK(std::fabs(q - kM * pf) <= 0.01 * kM * pf);
  CHECK(std::fabs(r.at(-1, "void_ratio") - kE0) <= 1e-12);
  CHECK(rel_err <= 1e-12);
  CHECK(worst_yield(r) <= 1e-9);
}

TEST_CASE("modified_cam_clay: isotropic and oedometric loading follow the NCL slope lambda",
          "[material][unit]") {
  // Reference: docs/verification.md B, e = e_N - lambda ln p' on the NCL. Isotropic loading from
  // pc0 = p'0 stays on the NCL from the first increment: exact up to round-off (tolerance
  // 1e-9 relative). Oedometric loading from an isotropic state turns onto the K0 line (constant
  // q/p'), along which p'/pc is constant, so the slope is lambda once the stress ratio has
  // settled: measured by least squares over the second half of a 30% axial strain, tolerance 1%.
  const auto iso = run(mcc(), path("isotropic", 0.3, 300));
  const double s_iso = -e_lnp_slope(iso, 0, iso.rows.size() - 1);
  const auto oed = run(mcc(), path("oedometer", 0.3, 600));
  const size_t n = oed.rows.size() - 1;
  const double s_oed = -e_lnp_slope(oed, n / 2, n);
  const double eta0 = oed.at(long(n / 2), "q") / oed.at(long(n / 2), "p");
  const double eta1 = oed.at(-1, "q") / oed.at(-1, "p");
  // Reported only: the stress ratio eta = q/p' of the K0 line, K0 = sigma'_h/sigma'_v =
  // (3 - eta)/(3 + 2 eta).
  std::printf(
      "MCC NCL slope: isotropic %.9f (rel err %.2e), oedometric (second half) %.6f (rel err "
      "%.2e), lambda %.3f; oedometer q/p' %.5f -> %.5f (K0 %.4f); max f/pc^2 iso %.2e oed "
      "%.2e\n",
      s_iso, std::fabs(s_iso - kLambda) / kLambda, s_oed, std::fabs(s_oed - kLambda) / kLambda,
      kLambda, eta0, eta1, (3 - eta1) / (3 + 2 * eta1), worst_yield(iso), worst_yield(oed));
  CHECK(std::fabs(s_iso - kLambda) <= 1e-9 * kLambda);
  CHECK(std::fabs(s_oed - kLambda) <= 0.01 * kLambda);
  CHECK(worst_yield(iso) <= 1e-9);
  CHECK(worst_yield(oed) <= 1e-9);
}

TEST_CASE("modified_cam_clay: unloading follows the swelling slope kappa", "[material][unit]") {
  // Reference: docs/verification.md B (unloading slope kappa): e = e_k - kappa ln p' inside the
  // yield surface, exact for the integrated elastic law. Isotropic: load 20% volumetric strain,
  // unload 2%; oedometer: load 20% axial, unload 1% (stays elastic). Slope by least squares
  // over the unloading rows; tolerance 1% (measured: round-off). pc must not change.
  for (const char* name : {"isotropic", "oedometer"}) {
    const bool iso = std::string(name) == "isotropic";
    const int n = 200;
    const double unload = iso ? 0.02 : 0.01;
    const auto r = run(mcc(), path(name, 0.2, n, unload));
    const size_t last = r.rows.size() - 1;
    const double slope = -e_lnp_slope(r, size_t(n), last);
    const double dpc = std::fabs(r.at(-1, "preconsolidation_pressure") -
                                 r.at(long(n), "preconsolidation_pressure"));
    std::printf(
        "MCC %s unloading (%zu increments): e-ln p' slope %.9f, kappa %.3f, rel err %.2e; p' "
        "%.0f -> %.0f Pa; pc change %.2e Pa\n",
        name, last - size_t(n), slope, kKappa, std::fabs(slope - kKappa) / kKappa,
        r.at(long(n), "p"), r.at(-1, "p"), dpc);
    CHECK(std::fabs(slope - kKappa) <= 0.01 * kKappa);
    CHECK(std::fabs(slope - kKappa) <= 1e-9 * kKappa);
    CHECK(dpc == 0);
  }
}

TEST_CASE("modified_cam_clay: response is independent of the increment size", "[material][unit]") {
  // Drained triaxial from the NCL to 20% axial strain in 50 and in 1000 increments: final q,
  // p' and void ratio agree within 1% (backward Euler is first order; 50 increments of 0.4%
  // strain are large for MCC with K = v p'/kappa; measured 0.8% in q). Undrained: 2 vs 1000
  // increments to 20% (two 10% increments, each solved by Newton directly), same tolerance.
  const auto a = run(mcc(), path("triaxial_drained", 0.2, 50));
  const auto b = run(mcc(), path("triaxial_drained", 0.2, 1000));
  const double dq = std::fabs(a.at(-1, "q") - b.at(-1, "q")) / b.at(-1, "q");
  const double dp = std::fabs(a.at(-1, "p") - b.at(-1, "p")) / b.at(-1, "p");
  const double de = std::fabs(a.at(-1, "void_ratio") - b.at(-1, "void_ratio"));
  const auto c = run(mcc(), path("triaxial_undrained", 0.2, 2));
  const auto d = run(mcc(), path("triaxial_undrained", 0.2, 1000));
  const double dqu = std::fabs(c.at(-1, "q") - d.at(-1, "q")) / d.at(-1, "q");
  const double dpu = std::fabs(c.at(-1, "p") - d.at(-1, "p")) / d.at(-1, "p");
  std::printf(
      "MCC drained triaxial 50 vs 1000 increments (20%% axial): q %.2f vs %.2f Pa (rel %.2e), "
      "p' rel %.2e, e abs %.2e; undrained 2 vs 1000: q %.2f vs %.2f (rel %.2e), p' rel %.2e; "
      "max f/pc^2 %.2e %.2e\n",
      a.at(-1, "q"), b.at(-1, "q"), dq, dp, de, c.at(-1, "q"), d.at(-1, "q"), dqu, dpu,
      worst_yield(a), worst_yield(c));
  CHECK(dq <= 0.01);
  CHECK(dp <= 0.01);
  CHECK(de <= 0.01);
  CHECK(dqu <= 0.01);
  CHECK(dpu <= 0.01);
  CHECK(worst_yield(a) <= 1e-9);
  CHECK(worst_yield(c) <= 1e-9);
}

TEST_CASE("modified_cam_clay: yield function is satisfied after every step of random paths",
          "[material][unit]") {
  // f = q^2/M^2 + p'(p' - pc) <= 1e-9 pc^2 after every step (the return converges to 1e-12;
  // elastic steps accept f <= 1e-10 pc^2), on random 3D strain paths with spin, from normally
  // and heavily overconsolidated states, with small and with large increments (up to ~5%
  // strain per step). Each path is a steady isochoric triaxial compression (5e-4 per step or
  // half the step size along x) plus random strain (mean-reverting, so it stays bounded) and
  // random spin.
  // Also 1D and 2D.
  std::mt19937 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  for (double size : {1e-4, 1e-3, 2e-2}) {
    for (double ocr : {1.0, 10.0}) {
      Point<3> pt(mcc(", pc0: 100e3"));
      pt.set({-kP0 / ocr, -kP0 / ocr, -kP0 / ocr, 0, 0, 0});
      pt.pc() = kP0;
      double worst = -1, plastic = 0;
      double N[3][3] = {};  // accumulated random strain
      for (int i = 0; i < 1000; ++i) {
        std::vector<double> l(9);
        for (int a = 0; a < 3; ++a)
          for (int b = a; b < 3; ++b) {
            const double dn = size * g(rng) - 0.1 * N[a][b];
            const double c = 0.5 * std::max(size, 1e-3);
            const double drift = a != b ? 0.0 : a == 0 ? -c : 0.5 * c;
            const double w = a == b ? 0.0 : size * g(rng);  // spin
            N[a][b] += dn, N[b][a] = N[a][b];
            l[size_t(3 * a + b)] = drift + dn + w;
            l[size_t(3 * b + a)] = drift + dn - w;
          }
        const double pc_before = pt.pc();
        pt.step(l);
        REQUIRE(std::isfinite(pt.stress(0)));
        REQUIRE(pt.pc() > 0);
        if (pt.pc() != pc_before) ++plastic;
        worst = std::max(worst, pt.f_rel());
      }
      std::printf(
          "MCC random 3D path (step size %.0e, OCR %.0f, 1000 steps, %.0f plastic): max "
          "f/pc^2 %.2e; final p' %.0f q %.0f pc %.0f Pa e %.4f\n",
          size, ocr, plastic, worst, pt.p(), pt.q(), pt.pc(), pt.e());
      CHECK(worst <= 1e-9);
      CHECK(plastic > 10);
    }
  }
  // 1D (confined) and 2D (plane strain) compression and extension cycles.
  Point<1> p1;
  p1.set({-kP0, -kP0, -kP0});
  Point<2> p2;
  p2.set({-kP0, -kP0, -kP0, 0});
  double w1 = -1, w2 = -1;
  for (int i = 0; i < 600; ++i) {
    const double s = (i / 100) % 2 == 0 ? -1e-3 : 5e-4;
    p1.step({s});
    p2.step({s, 2e-3 * std::sin(0.05 * i), -1e-3, -0.5 * s});
    w1 = std::max(w1, p1.f_rel());
    w2 = std::max(w2, p2.f_rel());
  }
  std::printf("MCC 1D and 2D cycles: max f/pc^2 %.2e %.2e; 2D sigma_zz %.0f Pa\n", w1, w2,
              p2.stress(2));
  CHECK(w1 <= 1e-9);
  CHECK(w2 <= 1e-9);
}

namespace {

struct Jump {
  const char* name;
  double ocr;
  std::vector<double> l;  // L dt, row-major 3x3
};

/// Single huge increments: 50% strain from normally and heavily overconsolidated states, and
/// two increments (found by a random search) on which Newton fails and the strain increment
/// is halved once or twice.
std::vector<Jump> jumps() {
  std::vector<Jump> j;
  for (double ocr : {1.0, 10.0}) {
    j.push_back(
        {"isotropic compression 50%", ocr, {-0.5 / 3, 0, 0, 0, -0.5 / 3, 0, 0, 0, -0.5 / 3}});
    j.push_back({"isotropic extension 30%", ocr, {0.1, 0, 0, 0, 0.1, 0, 0, 0, 0.1}});
    j.push_back({"triaxial compression 50%", ocr, {-0.5, 0, 0, 0, 0.25, 0, 0, 0, 0.25}});
    j.push_back({"triaxial extension 30%", ocr, {0.3, 0, 0, 0, -0.05, 0, 0, 0, -0.05}});
    j.push_back({"shear 50% with spin", ocr, {0, 0.5, 0, 0, 0, 0, 0, 0, 0}});
    j.push_back({"mixed 40%", ocr, {-0.4, 0.2, -0.1, 0.1, 0.2, 0.3, 0.05, -0.2, 0.1}});
  }
  j.push_back({"Newton fails, one halving",
               17.4583,
               {0.140325, 0.549276, -0.0776762, 0.380217, -0.309187, 0.217722, 0.170592, 0.171277,
                -0.540112}});
  j.push_back({"Newton fails, two halvings",
               9.35951,
               {0.283507, 0.440679, 0.000441942, 0.00747789, 0.278933, 0.0246693, 0.597329,
                -0.234343, 0.797904}});
  return j;
}

}  // namespace

TEST_CASE("modified_cam_clay: single huge increments stay admissible", "[material][unit]") {
  // Explicit MPM can hand a particle a large strain increment (impact, a particle crossing a
  // free surface). One increment of up to 50% strain (compression, extension, shear, with
  // spin) must give a finite stress on or inside the yield surface (f <= 1e-9 pc^2),
  // p' >= 0 and pc > 0; so must the two increments that need the sub-stepping fallback, and
  // every increment solved in one go by the bracketed return (return_mapping: bracketed).
  double worst = -1;
  for (const char* solver : {"newton", "bracketed"})
    for (const auto& c : jumps()) {
      Point<3> pt(mcc(", pc0: 100e3, return_mapping: " + std::string(solver)));
      pt.set({-kP0 / c.ocr, -kP0 / c.ocr, -kP0 / c.ocr, 0, 0, 0});
      pt.pc() = kP0;
      pt.step(c.l);
      const bool finite = std::isfinite(pt.p()) && std::isfinite(pt.q()) && std::isfinite(pt.pc());
      std::printf(
          "MCC one increment (%s), %s, OCR %.3g: p' %.6g q %.6g pc %.6g Pa e %.4f f/pc^2 %.2e\n",
          solver, c.name, c.ocr, pt.p(), pt.q(), pt.pc(), pt.e(), pt.f_rel());
      CHECK(finite);
      CHECK(pt.f_rel() <= 1e-9);
      CHECK(pt.p() >= -1e-9 * kP0);
      CHECK(pt.pc() > 0);
      worst = std::max(worst, pt.f_rel());
    }
  std::printf("MCC single huge increments: max f/pc^2 %.2e\n", worst);
}

TEST_CASE("modified_cam_clay: Newton and bracketed returns agree", "[material][unit]") {
  // The two solvers of the same backward Euler equations (return_mapping: newton, the default,
  // and bracketed, the last-resort scalar solver of the sub-stepping fallback) must give the
  // same stress to their tolerances: 1e-8 relative, on the huge single increments that Newton
  // solves without sub-stepping and along drained (NC) and undrained (OCR 10) triaxial paths.
  double worst = 0;
  for (const auto& c : jumps()) {
    if (std::string(c.name).rfind("Newton fails", 0) == 0) continue;  // sub-stepped: differs
    Point<3> a(mcc(", pc0: 100e3")), b(mcc(", pc0: 100e3, return_mapping: bracketed"));
    for (auto* pt : {&a, &b}) {
      pt->set({-kP0 / c.ocr, -kP0 / c.ocr, -kP0 / c.ocr, 0, 0, 0});
      pt->pc() = kP0;
      pt->step(c.l);
    }
    for (int k = 0; k < 6; ++k)
      worst = std::max(worst, std::fabs(a.stress(k) - b.stress(k)) / std::max(a.pc(), 1.0));
    worst = std::max(worst, std::fabs(a.pc() - b.pc()) / a.pc());
  }
  double worst_path = 0;
  for (auto [name, extra] :
       {std::pair{"triaxial_drained", ", ocr: 1"}, std::pair{"triaxial_undrained", ", ocr: 10"}}) {
    const auto a = run(mcc(extra), path(name, 0.2, 100));
    const auto b =
        run(mcc(std::string(extra) + ", return_mapping: bracketed"), path(name, 0.2, 100));
    for (size_t i = 0; i < a.rows.size(); ++i)
      for (const char* col : {"p", "q", "preconsolidation_pressure"})
        worst_path = std::max(worst_path, std::fabs(a.at(long(i), col) - b.at(long(i), col)) /
                                              a.at(long(i), "preconsolidation_pressure"));
  }
  std::printf(
      "MCC Newton vs bracketed return: single increments max difference / pc %.2e; triaxial "
      "paths (100 increments) %.2e\n",
      worst, worst_path);
  CHECK(worst <= 1e-8);
  CHECK(worst_path <= 1e-8);
}

TEST_CASE("modified_cam_clay: 1D confined compression equals the 3D oedometer",
          "[material][unit]") {
  // The 1D material point (stores xx yy zz) under uniaxial strain must give the element-test
  // oedometer (3D point, no lateral strain) to round-off: same stresses, void ratio, pc.
  const int n = 200;
  const auto r = run(mcc(), path("oedometer", 0.2, n));
  Point<1> pt(mcc(", ocr: 1"));
  pt.set({-kP0, -kP0, -kP0});
  for (int i = 0; i < n; ++i) pt.step({-0.2 / n});
  const double ds = std::max(std::fabs(-pt.stress(0) + r.at(-1, "sig_xx")),
                             std::fabs(-pt.stress(1) + r.at(-1, "sig_yy")));
  std::printf(
      "MCC 1D vs 3D oedometer: max stress difference %.2e Pa, e %.9f vs %.9f, pc %.3f vs %.3f\n",
      ds, pt.e(), r.at(-1, "void_ratio"), pt.pc(), r.at(-1, "preconsolidation_pressure"));
  CHECK(ds <= 1e-6 * kP0);
  CHECK(pt.e() == Approx(r.at(-1, "void_ratio")).epsilon(1e-12));
  CHECK(pt.pc() == Approx(r.at(-1, "preconsolidation_pressure")).epsilon(1e-10));
}

TEST_CASE("modified_cam_clay: a rigid rotation of a stressed point keeps its invariants",
          "[material][unit]") {
  // Jaumann objectivity: an overconsolidated plane-strain stress (inside the yield surface)
  // spun by 90 degrees in 1000 steps (L = [[0, -w], [w, 0]], tr d = 0) keeps p' to round-off
  // (the rotation is trace free) and stays elastic (pc, e unchanged). The framework's
  // first-order Jaumann update sigma += w sigma - sigma w rotates the in-plane deviator
  // (radius r = sqrt(((sxx - syy)/2)^2 + sxy^2)) while scaling it by exactly sqrt(1 + 4 w^2)
  // per step; with sigma_zz and the in-plane mean unchanged this predicts q to round-off
  // (tolerance 1e-9), and q drifts from its initial value by that factor only (~0.5% here,
  // tolerance 1%). The principal stresses swap: sigma_xx <-> sigma_yy within 1%.
  Point<2> pt;
  const double sx = -150e3, sy = -60e3, sz = -90e3;
  pt.set({sx, sy, sz, 0});
  pt.pc() = 300e3;
  const double p0 = pt.p(), q0 = pt.q(), e0 = pt.e();
  const int steps = 1000;
  const double w = M_PI / 2 / steps;
  double worst_p = 0;
  for (int i = 0; i < steps; ++i) {
    pt.step({0, -w, w, 0});
    worst_p = std::max(worst_p, std::fabs(pt.p() - p0) / p0);
  }
  const double c = 0.5 * (sx + sy),
               r = 0.5 * std::fabs(sx - sy) * std::pow(1 + 4 * w * w, 0.5 * steps);
  const double m = (2 * c + sz) / 3;  // q of principal stresses c + r, c - r, sz
  const double q_pred = std::sqrt(
      1.5 * ((c + r - m) * (c + r - m) + (c - r - m) * (c - r - m) + (sz - m) * (sz - m)));
  std::printf(
      "MCC rigid rotation 90 deg (1000 steps): max |dp'|/p' %.2e; q %.4f vs predicted %.4f Pa "
      "(rel %.2e), drift from q0 %.2e; xx %.1f (was yy %.1f) yy %.1f (was xx %.1f) xy %.1f Pa; "
      "pc %.3f e change %.2e\n",
      worst_p, pt.q(), q_pred, std::fabs(pt.q() - q_pred) / q_pred, std::fabs(pt.q() - q0) / q0,
      pt.stress(0), sy, pt.stress(1), sx, pt.stress(3), pt.pc(), std::fabs(pt.e() - e0));
  CHECK(worst_p <= 1e-12);
  CHECK(std::fabs(pt.q() - q_pred) <= 1e-9 * q_pred);
  CHECK(std::fabs(pt.q() - q0) <= 0.01 * q0);
  CHECK(pt.pc() == 300e3);
  CHECK(pt.e() == e0);
  CHECK(pt.stress(0) == Approx(sy).epsilon(0.01));
  CHECK(pt.stress(1) == Approx(sx).epsilon(0.01));
  CHECK(pt.stress(2) == Approx(sz).epsilon(1e-12));
}

TEST_CASE("modified_cam_clay: initial state, min_pressure and wave speed", "[material][unit]") {
  // initialize(): pc = ocr p'0, raised onto the yield surface for an initial stress with
  // q > 0 (pc = p' + q^2/(M^2 p')); e0 or v0 - 1. Wave speed: sqrt((K + 4G/3)/rho) with
  // K = v (p' + min_pressure)/kappa, G = 3K(1 - 2nu)/(2(1 + nu)) or the given G.
  Point<3> a(mcc(", ocr: 2, min_pressure: 1000"));
  a.set({-150e3, -75e3, -75e3, 0, 0, 0});  // p' = 100 kPa, q = 75 kPa
  const double pc_a = std::max(2 * 100e3, 100e3 + 75e3 * 75e3 / (kM * kM * 100e3));
  auto& P = a.sim->sets[0].particles;
  const double rho = P.col(P.mass)[0] / P.col(P.volume)[0];
  const double K = (1 + kE0) * (100e3 + 1000) / kKappa;
  const double G = 1.5 * K * (1 - 2 * kNu) / (1 + kNu);
  const double c_exact = std::sqrt((K + 4 * G / 3) / rho);
  const double c = a.sim->materials[0]->wave_speed(P, 0, P.size());
  Point<3> b(mcc(", pc0: 50e3, v0: 2.5, G: 3e6"));
  b.set({-150e3, -75e3, -75e3, 0, 0, 0});  // outside the pc0 = 50 kPa surface: raised
  const double pc_b = 100e3 + 75e3 * 75e3 / (kM * kM * 100e3);
  // A stress-free point with min_pressure compresses from p' = 0 along the shifted law.
  Point<3> z(mcc(", pc0: 100e3, min_pressure: 1000"));
  z.set({0, 0, 0, 0, 0, 0});
  for (int i = 0; i < 10; ++i) z.step({-1e-4, 0, 0, 0, -1e-4, 0, 0, 0, -1e-4});
  // Exact elastic law: ln((p' + pm)/pm) = (v0 - v)/kappa, v = v0 exp(tr eps), tr eps = -3e-3.
  const double pz = 1000 * std::expm1((1 + kE0) * -std::expm1(-3e-3) / kKappa);
  std::printf(
      "MCC initial state: pc %.3f (expected %.3f), raised pc %.3f (expected %.3f), e %.3f; "
      "wave speed %.4f m/s (expected %.4f); stress-free start with min_pressure: p' %.3f Pa "
      "(shifted law %.3f)\n",
      a.pc(), pc_a, b.pc(), pc_b, b.e(), c, c_exact, z.p(), pz);
  CHECK(a.pc() == Approx(pc_a).epsilon(1e-12));
  CHECK(b.pc() == Approx(pc_b).epsilon(1e-12));
  CHECK(b.e() == Approx(1.5).epsilon(1e-12));
  CHECK(c == Approx(c_exact).epsilon(1e-12));
  CHECK(z.p() == Approx(pz).epsilon(1e-9));
  CHECK(z.q() <= 1e-9);
}

TEST_CASE("modified_cam_clay: bad parameters give the located error", "[material][unit]") {
  // Each error is located at the offending value (column of the value in line 7), a missing
  // alternative at the material map itself (column 15).
  const std::vector<loam_test::BadMaterial> cases = {
      {"lambda: 0.1, kappa: 0.1, M: 1.2, nu: 0.3",
       ":7:91: error: bodies.0.material.kappa: swelling slope kappa = 0.1 must be smaller than "
       "the compression slope lambda = 0.1"},
      {"lambda: 0.2, kappa: 0.04, M: 0, nu: 0.3",
       ":7:100: error: bodies.0.material.M: 0 is out of range (0, inf)"},
      {"lambda: 0.2, kappa: 0.04, M: 1.2, nu: 0.5",
       ":7:109: error: bodies.0.material.nu: 0.5 is out of range [0, 0.5)"},
      {"lambda: 0.2, kappa: 0.04, M: 1.2, nu: 0.3, G: 5e6",
       ":7:117: error: bodies.0.material.G: give either 'nu' or 'G', not both"},
      {"lambda: 0.2, kappa: 0.04, M: 1.2, G: -5e6",
       ":7:108: error: bodies.0.material.G: -5000000 is out of range (0, inf) Pa"},
      {"lambda: 0.2, kappa: 0.04, M: 1.2",
       ":7:15: error: bodies.0.material: give exactly one of 'nu' or 'G'"},
  };
  loam_test::check_bad_material("type: modified_cam_clay, e0: 1, ocr: 1, density: 1800, ", cases);
}

TEST_CASE("modified_cam_clay: strength reduction divides tan phi_cs by F and keeps the state",
          "[material][unit]") {
  // Reference: docs/strength_reduction.md (Wood 1990): sin phi_cs = 3M / (6 + M), tan phi_F =
  // tan phi_cs / F, M_F = 6 sin phi_F / (3 - sin phi_F); M = 1.2 (phi_cs = 30 deg) at F = 1.25
  // gives M_F = 0.97489. The reduced model must follow the path of a model made with M_F from
  // the same state (stresses within 1e-9 relative over 400 steps of pure shear from p' = 100
  // kPa, pc = 200 kPa: the top of the ellipse), and end on q / p' = M_F within 1e-3.
  const double F = 1.25, s = 3 * kM / (6 + kM);
  const double sf = std::sin(std::atan(std::tan(std::asin(s)) / F));
  const double MF = 6 * sf / (3 - sf);
  char m_f[64];
  std::snprintf(m_f, sizeof m_f, "M: %.17g", MF);
  std::string with_mf = mcc(", ocr: 2");
  with_mf.replace(with_mf.find("M: 1.2"), 6, m_f);
  Point<3> a(mcc(", ocr: 2")), b(with_mf);
  for (auto* pt : {&a, &b}) pt->set({-kP0, -kP0, -kP0, 0, 0, 0});
  REQUIRE(a.pc() == Approx(2 * kP0));
  auto reduced = a.sim->materials[0]->reduced(F);
  REQUIRE(reduced);
  a.sim->materials[0] = std::move(reduced);
  double worst = 0;
  for (int i = 0; i < 400; ++i) {
    const std::vector<double> l = {1e-4, 0, 0, 0, -0.5e-4, 0, 0, 0, -0.5e-4};
    a.step(l);
    b.step(l);
    for (int k = 0; k < 6; ++k) worst = std::max(worst, std::fabs(a.stress(k) - b.stress(k)) / kP0);
  }
  std::printf(
      "MCC reduced by F = %.2f: M_F %.5f, q/p' %.5f at the end, max |sigma - sigma(M_F)| "
      "/ p'0 %.2e\n",
      F, MF, a.q() / a.p(), worst);
  CHECK(MF == Approx(0.97489).margin(5e-5));
  CHECK(worst <= 1e-9);
  CHECK(std::fabs(a.q() / a.p() / MF - 1) <= 1e-3);
}
