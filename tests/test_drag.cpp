// Drag laws (plugins/drag/darcy.cpp, plugins/drag/ergun.cpp) against hand-computed values
// (docs/verification.md D). Convention (framework/drag.hpp): Q is per unit MIXTURE volume, the
// force on the water is -Q (w - v), and Darcy's law q = n (w - v) = -(k/gamma_w) grad p gives Q =
// n^2 gamma_w / k = n^2 mu_w / kappa. Seed 001's coefficient per unit WATER volume, n gamma_w / k,
// is Q / n. No scheme uses drag yet, so parameters are validated here through
// loam::validate_plugin, exactly as a scheme's `drag:` key will validate them.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "framework/drag.hpp"
#include "framework/registry.hpp"

namespace {

struct Validated {
  loam::Params params;
  std::string errors;  // formatted diagnostics, "" if valid
};

Validated validate_drag(const std::string& yaml) {
  loam::ValidationContext ctx;
  ctx.file = "drag.yaml";
  ctx.dimension = 1;
  loam::Diagnostics diag;
  YAML::Node node = YAML::Load(yaml)["drag"];
  const loam::Location where = loam::location_of(node, "drag", ctx, {"drag.yaml", 1, 1});
  Validated v;
  v.params = loam::validate_plugin(node, "drag", loam::kDimension, "drag", where, ctx, diag);
  v.errors = diag.ok() ? "" : diag.format();
  return v;
}

std::unique_ptr<loam::Drag<1>> make_drag(const std::string& yaml) {
  Validated v = validate_drag(yaml);
  if (!v.errors.empty()) throw std::runtime_error(v.errors);
  return loam::Registry::instance().create<loam::Drag, 1>(v.params);
}

double Q_of(const loam::Drag<1>& drag, double n, double speed) {
  double Q = -1;
  drag.coefficient(1, &n, &speed, &Q);
  return Q;
}

double rel(double a, double b) {
  return std::fabs(a / b - 1);
}

}  // namespace

TEST_CASE("darcy: Q from the hydraulic conductivity against hand values", "[drag][unit]") {
  // Reference: k = 1e-3 m/s, rho_w = 1000, g = 9.81 -> gamma_w = 9810 N/m^3.
  //   n = 0.4: Q = n^2 gamma_w / k = 0.16 * 9810 / 1e-3 = 1.5696e6 kg/(m^3 s)
  //            (per unit water volume, seed 001: n gamma_w / k = 3.924e6)
  //   n = 0.3: Q = 0.09 * 9810 / 1e-3 = 8.829e5
  // Tolerance: 1e-14 relative (a few roundings).
  auto drag = make_drag("drag: {type: darcy, hydraulic_conductivity: 1.0e-3}");
  const double q4 = Q_of(*drag, 0.4, 0.0), q3 = Q_of(*drag, 0.3, 5.0);
  std::printf(
      "darcy(k): Q(0.4) = %.10g (hand 1.5696e6, rel err %.2e), Q(0.4)/n = %.10g (seed 001 "
      "n gamma_w/k = 3.924e6), Q(0.3) = %.10g (hand 8.829e5, rel err %.2e)\n",
      q4, rel(q4, 1.5696e6), q4 / 0.4, q3, rel(q3, 8.829e5));
  CHECK(rel(q4, 1.5696e6) < 1e-14);
  CHECK(rel(q4 / 0.4, 3.924e6) < 1e-14);
  CHECK(rel(q3, 8.829e5) < 1e-14);  // independent of |w - v|
  CHECK(drag->hydraulic_conductivity(0.3) == 1.0e-3);
  CHECK_FALSE(drag->speed_dependent());
  CHECK(drag->water_density() == 1000);
  CHECK(drag->water_viscosity() == 1.0e-3);
  // Darcy needs no relative speed: nullptr is allowed.
  double n = 0.4, Q = 0;
  drag->coefficient(1, &n, nullptr, &Q);
  CHECK(Q == q4);
}

TEST_CASE("darcy: Q from the intrinsic permeability against hand values", "[drag][unit]") {
  // Reference (seed 002): kappa = 1e-10 m^2, mu_w = 1e-3 Pa s, n = 0.3:
  //   Q = n^2 mu_w / kappa = 0.09 * 1e-3 / 1e-10 = 9e5 kg/(m^3 s),
  //   k = kappa gamma_w / mu_w = 1e-10 * 9810 / 1e-3 = 9.81e-4 m/s (docs/verification.md C: 1e-3).
  // With mu_w = 2e-3 both scale: Q = 1.8e6, k = 4.905e-4. Tolerance: 1e-14 relative.
  auto drag = make_drag("drag: {type: darcy, intrinsic_permeability: 1.0e-10}");
  const double Q = Q_of(*drag, 0.3, 0.0), k = drag->hydraulic_conductivity(0.3);
  auto viscous =
      make_drag("drag: {type: darcy, intrinsic_permeability: 1.0e-10, viscosity: 2.0e-3}");
  const double Q2 = Q_of(*viscous, 0.3, 0.0), k2 = viscous->hydraulic_conductivity(0.3);
  std::printf(
      "darcy(kappa): Q = %.10g (hand 9e5, rel err %.2e), k = %.10g m/s (hand 9.81e-4, rel "
      "err %.2e); mu_w = 2e-3: Q = %.10g, k = %.10g\n",
      Q, rel(Q, 9e5), k, rel(k, 9.81e-4), Q2, k2);
  CHECK(rel(Q, 9e5) < 1e-14);
  CHECK(rel(k, 9.81e-4) < 1e-14);
  CHECK(rel(Q2, 1.8e6) < 1e-14);
  CHECK(rel(k2, 4.905e-4) < 1e-14);
}

TEST_CASE("darcy: hydraulic and intrinsic parameterisations are equivalent", "[drag][unit]") {
  // Reference: kappa = k mu_w / gamma_w gives the same Q at every porosity (both are c n^2).
  // k = 2.5e-4 m/s, mu_w = 1.2e-3, rho_w = 998, g = 9.80665 -> kappa = 3.0651...e-11 m^2.
  // Batch of 1000 porosities in (0, 1). Tolerance: 1e-13 relative.
  const double k = 2.5e-4, mu = 1.2e-3, rho = 998, g = 9.80665, kappa = k * mu / (rho * g);
  const std::string water = "viscosity: 1.2e-3, density: 998, gravity: 9.80665";
  auto a = make_drag("drag: {type: darcy, hydraulic_conductivity: 2.5e-4, " + water + "}");
  char buf[200];
  std::snprintf(buf, sizeof buf, "drag: {type: darcy, intrinsic_permeability: %.17g, %s}", kappa,
                water.c_str());
  auto b = make_drag(buf);
  const size_t N = 1000;
  std::vector<double> n(N), s(N), Qa(N), Qb(N);
  for (size_t i = 0; i < N; ++i) n[i] = (double(i) + 0.5) / double(N), s[i] = 0.1 * double(i);
  a->coefficient(N, n.data(), s.data(), Qa.data());
  b->coefficient(N, n.data(), nullptr, Qb.data());
  double worst = 0, worst_hand = 0;
  for (size_t i = 0; i < N; ++i) {
    worst = std::max(worst, rel(Qa[i], Qb[i]));
    worst_hand = std::max(worst_hand, rel(Qa[i], n[i] * n[i] * rho * g / k));
  }
  std::printf(
      "darcy: k vs kappa over %zu porosities: max rel diff %.2e, vs n^2 gamma_w/k %.2e, "
      "k from kappa %.10g (given %.10g)\n",
      N, worst, worst_hand, b->hydraulic_conductivity(0.5), k);
  CHECK(worst < 1e-13);
  CHECK(worst_hand < 1e-13);
  CHECK(rel(b->hydraulic_conductivity(0.5), k) < 1e-13);
}

TEST_CASE("ergun: Q against hand values at two relative speeds", "[drag][unit]") {
  // Reference, d = 1e-3 m, n = 0.4, mu_w = 1e-3 Pa s, rho_w = 1000, A = 150, B = 1.75:
  //   kappa = d^2 n^3 / (A (1-n)^2) = 1e-6 * 0.064 / (150 * 0.36) = 1.185185e-9 m^2
  //   mu_w / kappa = 843750 kg/(m^3 s)           -> n^2 * 843750 = 135000
  //   F = B / (A^0.5 n^1.5) = 1.75 / (12.247449 * 0.252982) = 0.564810
  //   sqrt(kappa) = 3.442652e-5 m;  n rho_w F / sqrt(kappa) = 6.5625e6 kg/m^4
  //                                              -> n^2 * 6.5625e6 = 1.05e6 per (m/s)
  //   |w - v| = 0.01 m/s: Q = 135000 + 1.05e6 * 0.01 = 145500 kg/(m^3 s)
  //   |w - v| = 0.1 m/s:  Q = 135000 + 1.05e6 * 0.1  = 240000
  //   |w - v| = 0:        Q = 135000 (laminar)
  // The same Q from the formula as written in docs/verification.md D (pow, sqrt) is also compared,
  // and so is the classical Ergun gradient with flux U = n |w - v|:
  //   Q |w - v| / n = A mu (1-n)^2 U / (n^3 d^2) + B rho (1-n) U^2 / (n^3 d).
  // Tolerance: 1e-13 relative.
  auto drag = make_drag("drag: {type: ergun, grain_diameter: 1.0e-3}");
  const double n = 0.4, d = 1e-3, mu = 1e-3, rho = 1000, A = 150, B = 1.75;
  struct Case {
    double speed, hand;
  };
  for (Case c : {Case{0.01, 145500}, Case{0.1, 240000}, Case{0.0, 135000}}) {
    const double Q = Q_of(*drag, n, c.speed);
    const double kappa = d * d * std::pow(n, 3) / (A * std::pow(1 - n, 2));
    const double F = B / (std::sqrt(A) * std::pow(n, 1.5));
    const double Qformula = n * n * (mu / kappa + n * rho * F / std::sqrt(kappa) * c.speed);
    const double U = n * c.speed;
    const double grad = A * mu * std::pow(1 - n, 2) * U / (std::pow(n, 3) * d * d) +
                        B * rho * (1 - n) * U * U / (std::pow(n, 3) * d);
    std::printf("ergun: |w-v| = %g m/s: Q = %.12g (hand %g, rel err %.2e; D formula rel err %.2e)",
                c.speed, Q, c.hand, rel(Q, c.hand), rel(Q, Qformula));
    if (c.speed > 0) std::printf(", Ergun gradient rel err %.2e", rel(Q * c.speed / n, grad));
    std::printf("\n");
    CHECK(rel(Q, c.hand) < 1e-13);
    CHECK(rel(Q, Qformula) < 1e-13);
    if (c.speed > 0) CHECK(rel(Q * c.speed / n, grad) < 1e-13);
  }
  CHECK(drag->speed_dependent());
  // Limits: no skeleton, no drag.
  CHECK(Q_of(*drag, 1.0, 1.0) == 0.0);
}

TEST_CASE("ergun: the laminar limit equals Darcy with the Kozeny-Carman permeability",
          "[drag][unit]") {
  // Reference: for |w - v| -> 0 the Ergun Q is n^2 mu_w / kappa_KC(n), i.e. darcy with
  // intrinsic_permeability = kappa_KC(n) = d^2 n^3 / (A (1-n)^2); also hydraulic_conductivity
  // agrees (k = kappa gamma_w / mu_w). d = 0.258 mm (seed 003), n = 0.2 ... 0.8, mu_w = 1.1e-3,
  // A = 180 (Carman). A nullptr speed array means the laminar limit. Tolerance 1e-13 relative.
  auto ergun = make_drag(
      "drag: {type: ergun, grain_diameter: 0.258e-3, A: 180, B: 1.75, viscosity: 1.1e-3}");
  double worst = 0, worst_k = 0;
  for (double n : {0.2, 0.3, 0.43, 0.5, 0.65, 0.8}) {
    const double kappa = 0.258e-3 * 0.258e-3 * n * n * n / (180 * (1 - n) * (1 - n));
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "drag: {type: darcy, intrinsic_permeability: %.17g, viscosity: 1.1e-3}", kappa);
    auto darcy = make_drag(buf);
    double Qe = 0, Qd = Q_of(*darcy, n, 0.0);
    ergun->coefficient(1, &n, nullptr, &Qe);
    worst = std::max({worst, rel(Qe, Qd), rel(Q_of(*ergun, n, 0.0), Qd)});
    worst_k =
        std::max(worst_k, rel(ergun->hydraulic_conductivity(n), darcy->hydraulic_conductivity(n)));
    std::printf(
        "ergun laminar, n = %.2f: kappa_KC = %.6e m^2, k = %.6e m/s, Q = %.8g, Darcy %.8g\n", n,
        kappa, ergun->hydraulic_conductivity(n), Qe, Qd);
  }
  std::printf("ergun laminar vs darcy(kappa_KC): max rel diff Q %.2e, k %.2e\n", worst, worst_k);
  CHECK(worst < 1e-13);
  CHECK(worst_k < 1e-13);
}

TEST_CASE("ergun: a batch equals point-by-point evaluation", "[drag][unit]") {
  // Reference: the vectorised batch over 4099 points (not a multiple of any SIMD width) against
  // single-point calls of the same plugin. Tolerance: 1e-15 relative (same arithmetic).
  auto drag = make_drag("drag: {type: ergun, grain_diameter: 2.0e-4}");
  const size_t N = 4099;
  std::vector<double> n(N), s(N), Q(N);
  for (size_t i = 0; i < N; ++i)
    n[i] = 0.05 + 0.9 * double(i) / double(N), s[i] = 1e-3 * double(i % 37);
  drag->coefficient(N, n.data(), s.data(), Q.data());
  double worst = 0;
  for (size_t i = 0; i < N; ++i) worst = std::max(worst, rel(Q[i], Q_of(*drag, n[i], s[i])));
  std::printf("ergun batch of %zu vs single points: max rel diff %.2e\n", N, worst);
  CHECK(worst <= 1e-15);
}

TEST_CASE("darcy: bad parameters give the located error", "[drag][unit]") {
  // Reference: the standard FILE:LINE:COL: error: path: message (docs/architecture.md "Errors"),
  // one line each.
  struct Case {
    std::string yaml, error;
  };
  const std::vector<Case> cases = {
      {"drag: {type: darcy, hydraulic_conductivity: -1.0e-3}",
       "drag.yaml:1:45: error: drag.hydraulic_conductivity: -0.001 is out of range (0, inf) m/s"},
      {"drag: {type: darcy, intrinsic_permeability: 0}",
       "drag.yaml:1:45: error: drag.intrinsic_permeability: 0 is out of range (0, inf) m^2"},
      {"drag: {type: darcy, hydraulic_conductivity: 1.0e-3, intrinsic_permeability: 1.0e-10}",
       "drag.yaml:1:77: error: drag.intrinsic_permeability: give either hydraulic_conductivity or "
       "intrinsic_permeability, not both"},
      {"drag: {type: darcy}",
       "drag.yaml:1:7: error: drag: missing the permeability: give hydraulic_conductivity (m/s) or "
       "intrinsic_permeability (m^2)"},
      {"drag: {type: darcy, hydraulic_conductivity: 1.0e-3, viscosity: -1}",
       "drag.yaml:1:64: error: drag.viscosity: -1 is out of range (0, inf) Pa s"},
      {"drag: {type: darcy, permeability: 1.0e-3}",
       "drag.yaml:1:7: error: drag: missing the permeability: give hydraulic_conductivity (m/s) or "
       "intrinsic_permeability (m^2)\n"
       "drag.yaml:1:21: error: drag.permeability: unknown key 'permeability'; valid keys are: "
       "hydraulic_conductivity, intrinsic_permeability, viscosity, density, gravity"},
  };
  for (const auto& c : cases) {
    Validated v = validate_drag(c.yaml);
    std::printf("%s\n  -> %s", c.yaml.c_str(), v.errors.c_str());
    CHECK(v.errors == c.error + "\n");
  }
}

TEST_CASE("ergun: bad parameters give the located error", "[drag][unit]") {
  // Reference: the standard FILE:LINE:COL: error: path: message (docs/architecture.md "Errors"),
  // one line each.
  struct Case {
    std::string yaml, error;
  };
  const std::vector<Case> cases = {
      {"drag: {type: ergun, grain_diameter: -2.0e-4}",
       "drag.yaml:1:37: error: drag.grain_diameter: -0.0002 is out of range (0, inf) m"},
      {"drag: {type: ergun}",
       "drag.yaml:1:7: error: drag.grain_diameter: missing required key 'grain_diameter' "
       "(representative grain diameter d (fine sand ~2e-4), m)"},
      {"drag: {type: ergun, grain_diameter: 2.0e-4, A: 0}",
       "drag.yaml:1:48: error: drag.A: 0 is out of range (0, inf)"},
      {"drag: {type: ergun, grain_diameter: 2.0e-4, B: -1.75}",
       "drag.yaml:1:48: error: drag.B: -1.75 is out of range [0, inf)"},
  };
  for (const auto& c : cases) {
    Validated v = validate_drag(c.yaml);
    std::printf("%s\n  -> %s", c.yaml.c_str(), v.errors.c_str());
    CHECK(v.errors == c.error + "\n");
  }
}
