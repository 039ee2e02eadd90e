// Seed 001 MCC consolidation (configs/seed001_mcc.yaml; docs/verification.md C, "Seed 001 MCC"): a
// 1 m Modified Cam Clay column, normally consolidated at the isotropic effective stress 50 kPa,
// under 150 kPa more. Two references for the final settlement:
// - the closed-form normally consolidated oedometric settlement (e-ln p' on the NCL at the K0
//   stress ratio of the MCC flow rule; derived at closed_form() below), computed here from the
//   config's parameters without the material code, so a constitutive error cannot cancel;
// - loam's own oedometric element test of the same material from the same state to the same
//   final vertical effective stress (200 kPa; target: within 2 %, docs/seed001_mcc.md), run here
//   through loam::run_element_test on the material, initial stress and loads read from the config
//   file, so the target follows the config; the config's verify.expected_settlement must agree with
//   it.
// The element test must equal the closed form (checks the material point), and the column must
// equal both (checks the two-phase MPM column). The paper's 0.142 m is printed beside, with the
// settlements other parameter conventions give (see the config header).
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "cli.hpp"
#include "app/element_test.hpp"

namespace {

const std::string kConfig = std::string(LOAM_SOURCE_DIR) + "/configs/seed001_mcc.yaml";
constexpr double kPaper = 0.142;  // m, the paper's final settlement (FEM and MPM)

/// State of the element test where -sig_xx reaches a given vertical effective stress: linear
/// interpolation in ln(-sig_xx) between the two bracketing rows.
struct OedometerState {
  double eps_a = 0, e = 0, p = 0, q = 0, pc = 0;
};

OedometerState state_at(const loam::ElementTestResult& r, double sv) {
  for (size_t i = 1; i < r.rows.size(); ++i) {
    const double a = -r.at(long(i - 1), "sig_xx"), b = -r.at(long(i), "sig_xx");
    if (a < sv && sv <= b) {
      const double t = (std::log(sv) - std::log(a)) / (std::log(b) - std::log(a));
      auto f = [&](const char* c) {
        return r.at(long(i - 1), c) + t * (r.at(long(i), c) - r.at(long(i - 1), c));
      };
      return {f("eps_a"), f("void_ratio"), f("p"), f("q"), f("preconsolidation_pressure")};
    }
  }
  FAIL("the element test does not reach sigma'_v = " << sv << " Pa");
  return {};
}

/// The config's column and its oedometric element test.
struct Target {
  double H0 = 0, e0 = 0, lambda = 0, kappa = 0, M = 0, nu = 0;
  double sv0 = 0, sv = 0;     // initial and final vertical effective stress (Pa, compression +)
  double expected = 0;        // the config's verify.expected_settlement (m)
  OedometerState at_sv, at0;  // element test at sv and at sv0
  loam::ElementTestResult test;

  double settlement() const { return H0 * (1 - std::exp(-at_sv.eps_a)); }
};

Target target() {
  Target t;
  const YAML::Node cfg = YAML::LoadFile(kConfig);
  const YAML::Node body = cfg["bodies"][0];
  const YAML::Node mat = body["material"];
  t.H0 = body["generator"]["max"][0].as<double>() - body["generator"]["min"][0].as<double>();
  t.e0 = mat["e0"].as<double>();
  t.lambda = mat["lambda"].as<double>();
  t.kappa = mat["kappa"].as<double>();
  t.M = mat["M"].as<double>();
  REQUIRE(mat["nu"]);  // the closed form below assumes G = 3K(1 - 2nu)/(2(1 + nu))
  t.nu = mat["nu"].as<double>();
  REQUIRE(mat["ocr"].as<double>() == 1.0);  // normally consolidated: pc0 = p'0
  // The element test starts isotropic: the column's initial stress must be.
  const YAML::Node s = body["stress"];
  REQUIRE(s[0].as<double>() == s[1].as<double>());
  REQUIRE(s[0].as<double>() == s[2].as<double>());
  t.sv0 = -s[0].as<double>();
  // Drained, the vertical effective stress carries every traction on the top.
  for (const auto& load : cfg["loads"]) t.sv -= load["traction"][0].as<double>();
  t.expected = cfg["verify"]["expected_settlement"].as<double>();
  loam::ElementTest test;
  test.path = "oedometer";
  test.confining = t.sv0;
  test.strain = 0.3;  // beyond sigma'_v = 200 kPa (reached at 0.215)
  test.increments = 3000;
  YAML::Emitter out;
  out << YAML::Flow << mat;
  t.test = loam::run_element_test(out.c_str(), test);
  INFO(t.test.failure);
  REQUIRE(t.test.failure.empty());
  t.at_sv = state_at(t.test, t.sv);
  return t;
}

const Target& the_target() {
  static const Target t = target();
  return t;
}

/// The closed-form final state of a normally consolidated MCC soil loaded oedometrically (1D,
/// drained) to the vertical effective stress sv, from the parameters alone (no call into the
/// material). Derivation:
///
/// Volumetric law. materials/modified_cam_clay.cpp updates the specific volume v = 1 + e as
/// v_{n+1} = v_n exp(tr d) and takes deps_v = (v_n - v_{n+1})/v_n, so v_n deps_v = -de exactly:
/// its elastic law p' = p'_n exp(v_n deps_v^e / kappa) and hardening pc = pc_n exp(v_n deps_v^p
/// / (lambda - kappa)) are the e-ln p' lines de^e = -kappa d ln p', de^p = -(lambda - kappa)
/// d ln pc (slopes in e, NOT lambda* = lambda/(1 + e0) in ln v - ln p'). Summed from a normally
/// consolidated start (pc0 = p'0): e0 - e = lambda ln(pc/pc0) - kappa ln(pc/p'). On the yield
/// surface f = q^2/M^2 + p'(p' - pc) = 0, pc = p'(1 + eta^2/M^2), eta = q/p'. Every increment is
/// plastic (the path starts at the tip of the ellipse and loads monotonically), so e depends on
/// the final state only.
///
/// K0 of the NC oedometric path. Along a constant-eta path dp'/p' = dq/q = dpc/pc, hence
/// de = -lambda dp'/p' (the NCL slope lambda applies to p' on any constant-eta path) and, per
/// unit v, deps_v = lambda dp'/(v p'), deps_v^p = (lambda - kappa) dp'/(v p'). Shear: elastic
/// deps_q^e = dq/(3G), G = g K, K = v p'/kappa, g = 3(1 - 2nu)/(2(1 + nu)), so deps_q^e =
/// eta kappa/(3g) dp'/(v p'); plastic, by normality (associated flow),
/// deps_q^p/deps_v^p = (df/dq)/(df/dp') = (2q/M^2)/(2p' - pc) = 2 eta/(M^2 - eta^2). Zero lateral
/// strain: deps_q = 2/3 (deps_a - deps_h) = 2/3 deps_v. With the elastic strains included
/// (v cancels):
///     eta kappa/(3g) + (lambda - kappa) 2 eta/(M^2 - eta^2) = 2 lambda/3.
/// The left side increases from 0 (eta = 0) to infinity (eta -> M): one root eta_K0, by
/// bisection. K0 = sigma'_h/sigma'_v = (3 - eta)/(3 + 2 eta). (Ignoring the elastic strains,
/// kappa -> 0 on the left: 2 eta/(M^2 - eta^2) = 2/3, eta^2 + 3 eta - M^2 = 0; printed.)
///
/// Final state: p'_f = (1 + 2 K0) sv/3 = 3 sv/(3 + 2 eta), so
///     e0 - e_f = lambda ln(p'_f/p'_0) + (lambda - kappa) ln(1 + eta^2/M^2).
/// Settlement: confined, the height follows the volume, H/H0 = v/v0 at any strain, so
/// s = H0 (e0 - e_f)/(1 + e0) exactly (= H0 (1 - exp(-eps_a)), eps_a the logarithmic axial
/// strain); no small-strain approximation enters.
///
/// The column starts ISOTROPIC (eta = 0 at p'0 = 50 kPa), not on the K0 line, so the formula
/// needs the path to have reached eta_K0 by sv. path_to() integrates the same rate equations
/// from the isotropic state (RK4) to check that premise: eta - eta_K0 is -9e-8 at 100 kPa and
/// below 1e-11 from 150 kPa on, so at 200 kPa the closed form is exact.
struct ClosedForm {
  double eta = 0, K0 = 0, p = 0, pc = 0, de = 0, settlement = 0;
};

double shear_factor(double nu) {
  return 1.5 * (1 - 2 * nu) / (1 + nu);
}  // g = G/K

double eta_k0(const Target& t, bool elastic) {
  const double g = shear_factor(t.nu), kap = elastic ? t.kappa : 0.0, M2 = t.M * t.M;
  auto F = [&](double eta) {
    return eta * kap / (3 * g) + (t.lambda - kap) * 2 * eta / (M2 - eta * eta) - 2 * t.lambda / 3;
  };
  double lo = 0, hi = t.M;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (F(mid) > 0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

ClosedForm closed_form(const Target& t, double sv, bool elastic = true) {
  ClosedForm c;
  c.eta = eta_k0(t, elastic);
  c.K0 = (3 - c.eta) / (3 + 2 * c.eta);
  c.p = 3 * sv / (3 + 2 * c.eta);
  const double r = 1 + c.eta * c.eta / (t.M * t.M);
  c.pc = c.p * r;
  c.de = t.lambda * std::log(c.p / t.sv0) + (t.lambda - t.kappa) * std::log(r);
  c.settlement = t.H0 * c.de / (1 + t.e0);
  return c;
}

/// The oedometric path from the isotropic NC state (p' = pc = sv0, q = 0, v = 1 + e0) by RK4 on
/// the continuum rate equations of the model above, in the volumetric (logarithmic) strain
/// eps_v with deps_q = 2/3 deps_v: K = v p'/kappa, G = g K, plastic multiplier from the
/// consistency condition df = 0, dpc = pc v deps_v^p/(lambda - kappa), dv = -v deps_v. Stops
/// where sigma'_v = p' + 2q/3 reaches sv (linear interpolation within the last step).
struct PathState {
  double p = 0, q = 0, pc = 0, v = 0;
};

PathState path_to(const Target& t, double sv, double h = 1e-5) {
  const double g = shear_factor(t.nu), M2 = t.M * t.M, lk = t.lambda - t.kappa;
  auto rate = [&](const PathState& y) {
    const double K = y.v * y.p / t.kappa, G = g * K, fq = 2 * y.q / M2, fp = 2 * y.p - y.pc;
    const double dev = 1, deq = 2.0 / 3.0;
    const double L = (fq * 3 * G * deq + fp * K * dev) /
                     (3 * G * fq * fq + K * fp * fp + y.p * y.pc * y.v * fp / lk);
    return PathState{K * (dev - L * fp), 3 * G * (deq - L * fq), y.pc * y.v * L * fp / lk,
                     -y.v * dev};
  };
  auto axpy = [](const PathState& y, double a, const PathState& k) {
    return PathState{y.p + a * k.p, y.q + a * k.q, y.pc + a * k.pc, y.v + a * k.v};
  };
  PathState y{t.sv0, 0, t.sv0, 1 + t.e0};
  for (int i = 0; i < 10000000; ++i) {
    const PathState k1 = rate(y), k2 = rate(axpy(y, h / 2, k1)), k3 = rate(axpy(y, h / 2, k2)),
                    k4 = rate(axpy(y, h, k3));
    PathState n;
    n.p = y.p + h / 6 * (k1.p + 2 * k2.p + 2 * k3.p + k4.p);
    n.q = y.q + h / 6 * (k1.q + 2 * k2.q + 2 * k3.q + k4.q);
    n.pc = y.pc + h / 6 * (k1.pc + 2 * k2.pc + 2 * k3.pc + k4.pc);
    n.v = y.v + h / 6 * (k1.v + 2 * k2.v + 2 * k3.v + k4.v);
    const double s0 = y.p + 2 * y.q / 3, s1 = n.p + 2 * n.q / 3;
    if (s1 >= sv) {
      const double a = (sv - s0) / (s1 - s0);
      return PathState{y.p + a * (n.p - y.p), y.q + a * (n.q - y.q), y.pc + a * (n.pc - y.pc),
                       y.v + a * (n.v - y.v)};
    }
    y = n;
  }
  FAIL("the RK4 oedometric path does not reach sigma'_v = " << sv << " Pa");
  return y;
}

const ClosedForm& the_closed_form() {
  static const ClosedForm c = closed_form(the_target(), the_target().sv);
  return c;
}

nlohmann::json run_column(const std::string& extra, double tol) {
  loam_test::TempDir dir("seed001_mcc");
  auto s = loam_test::run_scene("seed001_mcc.yaml", dir.path, "--threads 1" + extra);
  const auto& t = the_target();
  const auto& c = the_closed_form();
  auto v = s["verify"];
  const double mpm = v["final_settlement"].get<double>();
  std::printf(
      "seed001_mcc%s:\n  final settlement MPM %.6f m; closed form %.6f m, error %+.2e; element "
      "test %.6f m, error %+.2e (tolerance %g); paper %.3f m (MPM %+.1f %%)\n  residual "
      "max|p|/q %.1e, mean sigma'_v %.0f Pa (drained: %.0f); %ld steps, %.1f s wall\n",
      extra.c_str(), mpm, c.settlement, mpm / c.settlement - 1, t.settlement(),
      mpm / t.settlement() - 1, tol, kPaper, 100 * (mpm / kPaper - 1),
      v["residual_pore_pressure"].get<double>(), v["vertical_stress"].get<double>(), t.sv,
      s["steps"].get<long>(), s["wall_seconds"].get<double>());
  return v;
}

/// The acceptance checks of a run: the closed-form settlement and the element test's within
/// `tol` (relative), drained.
void check_column(const std::string& extra, double tol) {
  const auto v = run_column(extra, tol);
  const auto& t = the_target();
  const double mpm = v["final_settlement"].get<double>();
  CHECK(std::fabs(mpm / the_closed_form().settlement - 1) <= tol);
  CHECK(std::fabs(mpm / t.settlement() - 1) <= tol);
  // Drained: the load has moved to the skeleton (else the settlement is not the final one).
  CHECK(v["residual_pore_pressure"].get<double>() <= 0.01);
  CHECK(v["vertical_stress"].get<double>() == Approx(t.sv).epsilon(0.01));
}

}  // namespace

TEST_CASE("seed001 MCC: the oedometric element test target and the paper's conventions",
          "[verification][two_phase][mcc]") {
  const auto& t = the_target();
  const auto& a = t.at_sv;
  const double K0 = (3 * a.p - t.sv) / (2 * t.sv);
  // Normally consolidated oedometric loading stays on the yield surface, so the void ratio
  // follows from the stress state alone: e0 - e = lambda ln(pc / pc0) - kappa ln(pc / p')
  // (pc0 = p'0 = sigma'_v0, ocr = 1). Checks the interpolated state and the e-ln p' laws.
  const double de = t.lambda * std::log(a.pc / t.sv0) - t.kappa * std::log(a.pc / a.p);
  // The column height follows its volume: H / H0 = (1 + e)/(1 + e0) = exp(-eps_a).
  const double by_e = t.H0 * (t.e0 - a.e) / (1 + t.e0);
  // Other conventions (config header): lambda* = lambda/(1 + e0) per ln p' in logarithmic
  // volumetric strain gives ln(H0/H) = (e0 - e)/(1 + e0) on the same stress path; and the
  // final stress 150 kPa instead of 200.
  const auto at150 = state_at(t.test, 150e3);
  auto lambda_star = [&](double e) { return t.H0 * (1 - std::exp(-(t.e0 - e) / (1 + t.e0))); };
  std::printf(
      "seed001 MCC element test (oedometer from %.0f kPa isotropic, NC): at sigma'_v = %.0f kPa "
      "eps_a = %.6f, settlement %.6f m (from e: %.6f; config expected_settlement %.6f), K0 "
      "%.4f, e0 - e = %.6f vs lambda ln(pc/pc0) - kappa ln(pc/p') = %.6f\n"
      "  paper %.3f m; other conventions: lambda* in log strain %.4f m; final 150 kPa: e-ln p' "
      "%.4f m, lambda* %.4f m (no reading with a final 200 kPa gives 0.142 m: config header)\n",
      t.sv0 / 1e3, t.sv / 1e3, a.eps_a, t.settlement(), by_e, t.expected, K0, t.e0 - a.e, de,
      kPaper, lambda_star(a.e), t.H0 * (t.e0 - at150.e) / (1 + t.e0), lambda_star(at150.e));
  CHECK(t.sv == Approx(200e3).epsilon(1e-12));
  CHECK(std::fabs((t.e0 - a.e) - de) <= 1e-6);
  CHECK(std::fabs(by_e - t.settlement()) <= 1e-6 * t.H0);
  // The number in the config (its verify block and header) is this element test's.
  CHECK(std::fabs(t.expected / t.settlement() - 1) <= 1e-5);
}

TEST_CASE("seed001 MCC: the element test equals the closed-form NC oedometric settlement",
          "[verification][mcc]") {
  // Reference: closed_form() (derivation above): eta_K0 from normality with zero lateral strain
  // (elastic strains included), e0 - e_f = lambda ln(p'_f/p'_0) + (lambda - kappa) ln(1 +
  // eta^2/M^2), s = H0 (e0 - e_f)/(1 + e0). Its premise (the path from the isotropic start has
  // reached the K0 line by 200 kPa) is checked by path_to(): eta within 1e-9 of eta_K0 and the
  // same settlement to 1e-9 m (RK4 with 2e4 steps, error ~1e-12). The element test (backward
  // Euler, 3000 increments of 1e-4 axial strain, read by interpolation in ln sigma'_v) must be
  // the closed form: settlement to 1e-5 relative and K0 to 1e-4 (measured: see the output;
  // its e-ln p' laws are exact per increment; measured -2.1e-7 and -6.9e-6, from the finite
  // increments and the interpolation between rows), tolerances 1e-6 and 3e-5.
  const auto& t = the_target();
  const auto& c = the_closed_form();
  const ClosedForm rigid = closed_form(t, t.sv, false);
  const PathState end = path_to(t, t.sv), mid = path_to(t, 100e3);
  const double s_path = t.H0 * (1 + t.e0 - end.v) / (1 + t.e0);
  const double K0_et = (3 * t.at_sv.p - t.sv) / (2 * t.sv);
  std::printf(
      "seed001 MCC closed form (NC oedometric, e-ln p'): eta_K0 = %.6f, K0 = %.6f, p'_f = %.1f "
      "Pa, pc_f = %.1f Pa, e0 - e_f = %.6f, settlement %.6f m\n"
      "  RK4 path from the isotropic state: eta at 100 kPa %.9f (%+.1e), at 200 kPa %.12f "
      "(%+.1e); settlement %.9f m (%+.1e m)\n"
      "  element test: settlement %.6f m (%+.2e relative), K0 %.6f (%+.1e); without elastic "
      "strains: eta %.4f, K0 %.4f, settlement %.4f m; lambda* = lambda/(1 + e0) in ln v: %.4f m\n",
      c.eta, c.K0, c.p, c.pc, c.de, c.settlement, mid.q / mid.p, mid.q / mid.p - c.eta,
      end.q / end.p, end.q / end.p - c.eta, s_path, s_path - c.settlement, t.settlement(),
      t.settlement() / c.settlement - 1, K0_et, K0_et - c.K0, rigid.eta, rigid.K0, rigid.settlement,
      t.H0 * (1 - std::exp(-c.de / (1 + t.e0))));
  CHECK(std::fabs(end.q / end.p - c.eta) <= 1e-9);
  CHECK(std::fabs(s_path - c.settlement) <= 1e-9 * t.H0);
  CHECK(std::fabs(t.settlement() / c.settlement - 1) <= 1e-6);
  CHECK(std::fabs(K0_et - c.K0) <= 3e-5);
}

TEST_CASE("seed001 MCC: step-loaded column within 0.5 % of the closed form",
          "[verification][two_phase][mcc]") {
  // References: the closed form (0.193764 m) and the element test (equal to it to 2e-7).
  // The final settlement is a drained equilibrium, independent of the water's bulk modulus:
  // K_w = 2.2e7 here (Skempton B >= 0.90 at the start; 3x fewer steps; the config's 2.2e8 and
  // 2.2e9 give the same settlement to 2e-4). The hydraulic conductivity is NOT raised: under
  // the step load the MCC settlement depends on k through the dynamics of the loading (faster
  // drainage overloads the top particles, whose extra plastic compression stays; measured
  // +0.31 % at k = 3e-3, +1.6 % at 3e-2, +2.2 % at 5e-2). Drained at 10 s.
  // Measured: +0.335 % (docs/seed001_mcc.md: +0.31 % with the code of that note). The excess
  // is the physical overshoot of the step load, not a discretisation error (ramped, the same
  // column is the closed form to 3e-5: next test). Tolerance 0.5 % (was 2 %, the target of
  // docs/seed001_mcc.md): room for +-0.15 % change of that dynamic excess; a constitutive error, a
  // wrong K0 (rigid-plastic K0: +0.10 %) or an undrained end (B = 0.9) would still fail the ramped
  // test.
  check_column(
      " --set scheme.water_bulk_modulus=2.2e7 --set time.end=10 --set output.every_time=10", 5e-3);
}

TEST_CASE("seed001 MCC: with the load ramped, the column is the closed form to 1e-4",
          "[verification][two_phase][mcc]") {
  // References: the closed form and the element test. Quasi-static loading (the 150 kPa
  // ramped over 0.5 s) leaves every particle on the NC oedometric path, so the settlement must
  // be the closed form's to the discretisation error (measured -3e-6 with the config's k and a
  // 2 s ramp); here with k = 0.05 m/s, K_w = 2.2e7, drained at 2 s: measured +2.6e-5 (the
  // particle volume follows det(I + L dt), the material's v exp(tr d): second order per step,
  // plus what inertia the 0.5 s ramp leaves). Tolerance 1e-4 (was 1e-3).
  check_column(
      " --set scheme.drag.hydraulic_conductivity=0.05 --set scheme.water_bulk_modulus=2.2e7"
      " --set loads.1.ramp_time=0.5 --set time.end=2 --set output.every_time=2",
      1e-4);
}

TEST_CASE("seed001 MCC: the paper's configuration (step load, k = 3e-3, 15 s)",
          "[verification][two_phase][mcc][full]") {
  // References as above. Measured +0.308 % (the step-load overshoot; docs/seed001_mcc.md).
  // Tolerance 0.5 % (was 2 %), as the quick step-load test.
  check_column("", 5e-3);
}
