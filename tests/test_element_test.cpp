// The element-test driver (app/element_test.hpp) on linear elasticity, where every path has
// a closed form (docs/verification.md B: the driver itself must be exact before it judges soils),
// and `loam element-test` through the command line: CSV, exit codes, located errors, no overwrite.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cli.hpp"
#include "app/element_test.hpp"

namespace {

constexpr double kE = 20e6, kNu = 0.3;
const double kG = kE / (2 * (1 + kNu)), kK = kE / (3 * (1 - 2 * kNu)),
             kLambda = kE * kNu / ((1 + kNu) * (1 - 2 * kNu));
const std::string kElastic = "{type: linear_elastic, E: 20.0e6, nu: 0.3, density: 2000}";

loam::ElementTest path(const std::string& name, double strain, int n = 50) {
  loam::ElementTest t;
  t.path = name;
  t.confining = 100e3;
  t.strain = strain;
  t.increments = n;
  return t;
}

double rel(double a, double b) {
  return std::fabs(a - b) / std::fabs(b);
}

}  // namespace

TEST_CASE(
    "element-test: drained triaxial on linear elasticity gives q = E eps_a, eps_lat = -nu eps_a",
    "[element_test][unit]") {
  // Small-strain closed form at constant lateral stress: d sigma_a = E d eps_a,
  // d eps_lateral = -nu d eps_a. Tolerance 1e-9 (the driver holds sigma_lat to 1e-10 p'0).
  auto r = loam::run_element_test(kElastic, path("triaxial_drained", 1e-3));
  REQUIRE(r.failure.empty());
  const double q = r.at(-1, "q"), ea = r.at(-1, "eps_a");
  const double lat = r.at(-1, "eps_yy");
  std::printf("triaxial_drained elastic: q/(E eps_a) - 1 = %.2e, eps_yy/(nu eps_a) - 1 = %.2e\n",
              q / (kE * ea) - 1, lat / (kNu * ea) - 1);
  CHECK(rel(q, kE * ea) < 1e-9);
  CHECK(rel(lat, kNu * ea) < 1e-9);
  CHECK(r.at(-1, "eps_zz") == Approx(lat).epsilon(1e-12));
  CHECK(r.at(-1, "sig_yy") == Approx(-100e3).epsilon(1e-9));
  CHECK(r.rows.size() == 51);
}

TEST_CASE("element-test: oedometer, isotropic and undrained paths on linear elasticity",
          "[element_test][unit]") {
  // Oedometer: sigma_a = -p0 - (lambda + 2G) eps_a, sigma_lat = -p0 - lambda eps_a.
  // Isotropic: p' = p0 + K eps_v.  Undrained (isochoric): p' = p0, q = 3 G eps_a.
  auto oed = loam::run_element_test(kElastic, path("oedometer", 1e-3));
  auto iso = loam::run_element_test(kElastic, path("isotropic", 1e-3));
  auto und = loam::run_element_test(kElastic, path("triaxial_undrained", 1e-3));
  REQUIRE(oed.failure.empty());
  REQUIRE(iso.failure.empty());
  REQUIRE(und.failure.empty());
  const double e_oed = rel(-oed.at(-1, "sig_xx") - 100e3, (kLambda + 2 * kG) * 1e-3);
  const double e_lat = rel(-oed.at(-1, "sig_yy") - 100e3, kLambda * 1e-3);
  const double e_iso = rel(iso.at(-1, "p") - 100e3, kK * 1e-3);
  const double e_und = rel(und.at(-1, "q"), 3 * kG * 1e-3);
  std::printf("oedometer %.2e, lateral %.2e, isotropic %.2e, undrained q %.2e, p' drift %.2e Pa\n",
              e_oed, e_lat, e_iso, e_und, std::fabs(und.at(-1, "p") - 100e3));
  CHECK(e_oed < 1e-9);
  CHECK(e_lat < 1e-9);
  CHECK(e_iso < 1e-9);
  CHECK(e_und < 1e-9);
  CHECK(std::fabs(und.at(-1, "p") - 100e3) < 1e-6);
  CHECK(iso.at(-1, "eps_v") == Approx(1e-3).epsilon(1e-12));
}

TEST_CASE("element-test: oedometer unloading returns along the loading line",
          "[element_test][unit]") {
  // Linear elasticity has no hysteresis: unloading the whole strain restores p0 exactly.
  auto t = path("oedometer", 2e-3, 40);
  t.unload_strain = 2e-3;
  auto r = loam::run_element_test(kElastic, t);
  REQUIRE(r.failure.empty());
  REQUIRE(r.rows.size() == 81);
  std::printf("oedometer load-unload: final sig_xx + p0 = %.3e Pa, eps_a = %.3e\n",
              r.at(-1, "sig_xx") + 100e3, r.at(-1, "eps_a"));
  CHECK(std::fabs(r.at(-1, "sig_xx") + 100e3) < 1e-6);
  CHECK(std::fabs(r.at(-1, "eps_a")) < 1e-15);
  CHECK(r.at(40, "eps_a") == Approx(2e-3).epsilon(1e-12));
}

TEST_CASE("element-test: simple shear on linear elasticity gives tau = G gamma",
          "[element_test][unit]") {
  // tau = G gamma to first order; the Jaumann rate adds O(gamma^2) normal stresses, so at
  // gamma = 1e-4 the relative error bound is 1e-3.
  auto r = loam::run_element_test(kElastic, path("simple_shear", 1e-4));
  REQUIRE(r.failure.empty());
  const double err = rel(r.at(-1, "sig_xy"), kG * 1e-4);
  std::printf("simple shear: tau/(G gamma) - 1 = %.2e, sig_yy + p0 = %.2e Pa\n", err,
              r.at(-1, "sig_yy") + 100e3);
  CHECK(err < 1e-3);
  CHECK(std::fabs(r.at(-1, "sig_yy") + 100e3) < 1e-5);
  CHECK(r.at(-1, "eps_xy") == Approx(0.5e-4).epsilon(1e-12));
}

TEST_CASE("element-test: state fields of the material become CSV columns", "[element_test][unit]") {
  auto r = loam::run_element_test(
      "{type: mohr_coulomb, E: 20.0e6, nu: 0.3, density: 2000, c: 0, phi: 30, psi: 0}",
      path("triaxial_drained", 0.02));
  REQUIRE(r.failure.empty());
  REQUIRE(r.column("plastic_strain_eq") >= 0);
  CHECK(r.at(-1, "plastic_strain_eq") > 0);
  CHECK(r.at(0, "plastic_strain_eq") == 0);
  CHECK_THROWS_AS(r.at(0, "no_such_column"), std::out_of_range);
  CHECK_THROWS_AS(loam::run_element_test("{type: mohr_coulomb, E: 1}", path("isotropic", 0.01)),
                  std::runtime_error);
}

TEST_CASE("element-test: the command line writes a CSV and never overwrites results",
          "[element_test][cli]") {
  loam_test::TempDir dir("element_test_cli");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "oed.yaml";
  std::ofstream(cfg) << "material: " << kElastic
                     << "\ntest: {path: oedometer, strain: 0.001, increments: 10}\n";
  const auto out = dir.path / "out";
  auto r = loam_test::run_loam("element-test " + cfg.string() + " --quiet --out " + out.string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  REQUIRE(std::filesystem::exists(out / "oed.csv"));
  std::ifstream in(out / "oed.csv");
  std::string header;
  std::getline(in, header);
  CHECK(header.rfind("step,eps_xx,", 0) == 0);
  int lines = 0;
  for (std::string l; std::getline(in, l);) ++lines;
  CHECK(lines == 11);
  // A second run into the same directory is refused (exit 2), the CSV left as it was.
  const auto before = std::filesystem::last_write_time(out / "oed.csv");
  auto again =
      loam_test::run_loam("element-test " + cfg.string() + " --quiet --out " + out.string());
  CHECK(again.exit_code == 2);
  CHECK(again.output.find("is not empty; pass --overwrite") != std::string::npos);
  CHECK(std::filesystem::last_write_time(out / "oed.csv") == before);
}

TEST_CASE("element-test: bad input gives every located error at once, exit code 2",
          "[element_test][cli]") {
  loam_test::TempDir dir("element_test_bad");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "bad.yaml";
  std::ofstream(cfg) << "material: {type: linear_elastik, E: 1.0e6, nu: 0.3, density: 1}\n"
                        "test:\n"
                        "  path: triaxial_drianed\n"
                        "  strain: 0.1\n"
                        "  increments: 0\n";
  const auto out = dir.path / "out";
  auto r = loam_test::run_loam("element-test " + cfg.string() + " --quiet --out " + out.string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  const std::string f = cfg.string();
  CHECK(r.output.find(f + ":1:18: error: material.type: unknown material 'linear_elastik'") !=
        std::string::npos);
  CHECK(r.output.find(f + ":3:9: error: test.path:") != std::string::npos);
  CHECK(r.output.find("did you mean 'triaxial_drained'") != std::string::npos);
  CHECK(r.output.find(f + ":5:15: error: test.increments:") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(out));
  // Unloading is refused on a path that has no unloading stage.
  std::ofstream(cfg) << "material: " << kElastic
                     << "\ntest: {path: simple_shear, strain: 0.1, unload_strain: 0.05}\n";
  r = loam_test::run_loam("element-test " + cfg.string() + " --quiet --out " + out.string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("error: test.unload_strain: unloading is available for the oedometer and "
                      "isotropic paths, not simple_shear") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(out));
}

TEST_CASE("element-test: the particle mass follows the tested material's density",
          "[element_test][unit]") {
  // newtonian_fluid reads its pressure from m / V: an isotropic compression by eps_v gives
  // p = K (rho/rho0 - 1) = K (V0/V - 1) with V/V0 = prod(1 - eps_v/3/n)^(3n) (det(I + L dt)
  // per increment, the scheme's volume update). Hand value to 1e-9.
  auto t = path("isotropic", 1e-3, 10);
  t.confining = 0;
  auto r = loam::run_element_test(
      "{type: newtonian_fluid, bulk_modulus: 2.0e6, viscosity: 0, density: 1000}", t);
  REQUIRE(r.failure.empty());
  const double ratio = std::pow(1 - 1e-3 / 3 / 10, 3 * 10);
  const double expected = 2.0e6 * (1 / ratio - 1);
  const double err = rel(r.at(-1, "p"), expected);
  std::printf("fluid through the driver: p = %.6f Pa (hand %.6f), error %.2e\n", r.at(-1, "p"),
              expected, err);
  CHECK(err < 1e-9);
}
