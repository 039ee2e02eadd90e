// Plausibility warnings (ParamSpec::plausible, materials/plausible.hpp; docs/runs.md "Warnings"):
// a legal value that is almost surely a unit slip is reported like an error, located, but the
// run goes on; `accept_warnings:` silences a key; no shipped run file warns.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "cli.hpp"
#include "framework/config.hpp"
#include "framework/runner.hpp"

using Catch::Matchers::Contains;

namespace {

/// The granular collapse's sand with `material` and `extra` top-level lines, as a run file.
std::string sand_column(const std::string& material, const std::string& extra = "") {
  return "grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.1}\n"
         "bodies:\n"
         "  - name: sand\n"
         "    generator: {type: box, min: [0, 0], max: [0.5, 0.5]}\n"
         "    material: {type: mohr_coulomb, " +
         material +
         ", nu: 0.3, c: 0, psi: 0}\n"
         "time: {end: 0.01}\n" +
         extra;
}

loam_test::CliResult check(const loam_test::TempDir& dir, const std::string& yaml,
                           const std::string& args = "") {
  std::filesystem::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml") << yaml;
  return loam_test::run_loam("check " + (dir.path / "run.yaml").string() + " " + args);
}

}  // namespace

TEST_CASE("plausibility: unit slips warn, located, and the run goes on", "[config][cli]") {
  // The three slips: phi in radians (0.52), E in MPa (5), density in t/m^3 (1.8).
  loam_test::TempDir dir("plausible");
  const auto r = check(dir, sand_column("E: 5, density: 1.8, phi: 0.52"));
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  const std::string file = (dir.path / "run.yaml").string();
  CHECK_THAT(r.output, Contains(file + ":5:39: warning: bodies.0.material.E: 5 Pa is outside "
                                       "the plausible [1000, "));
  CHECK_THAT(r.output, Contains(file + ":5:51: warning: bodies.0.material.density: 1.8 kg/m^3"));
  CHECK_THAT(r.output, Contains(file + ":5:61: warning: bodies.0.material.phi: 0.52 deg"));
  CHECK_THAT(r.output, Contains("radians"));
  CHECK_THAT(r.output, Contains(": ok (2D"));
  // Plausible values and phi = 0 (a Tresca-like material): nothing to say.
  const auto quiet = check(dir, sand_column("E: 5.0e6, density: 1800, phi: 0"));
  CHECK(quiet.exit_code == 0);
  CHECK_THAT(quiet.output, !Contains("warning"));
}

TEST_CASE("plausibility: accept_warnings silences each key, and names a key without one",
          "[config][cli]") {
  loam_test::TempDir dir("plausible_accept");
  const std::string slips = "E: 5, density: 1.8, phi: 0.52";
  for (const char* key : {"E", "density", "phi"}) {
    const std::string path = std::string("bodies.0.material.") + key;
    const auto r = check(dir, sand_column(slips, "accept_warnings: [" + path + "]\n"));
    std::printf("accepting %s:\n%s", path.c_str(), r.output.c_str());
    CHECK(r.exit_code == 0);
    CHECK_THAT(r.output, !Contains("warning: " + path + ":"));
    // the two others still warn
    int warnings = 0;
    for (size_t at = r.output.find("warning:"); at != std::string::npos;
         at = r.output.find("warning:", at + 1))
      ++warnings;
    CHECK(warnings == 2);
  }
  const auto r = check(dir, sand_column("E: 5.0e6, density: 1800, phi: 30",
                                        "accept_warnings: [bodies.0.material.phi]\n"));
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.output, Contains("run.yaml:7:19: warning: accept_warnings.0: "
                                "'bodies.0.material.phi' has no warning to accept"));
}

TEST_CASE("plausibility: an invalid run file prints its errors only, a --quiet run none",
          "[config][cli]") {
  loam_test::TempDir dir("plausible_errors");
  std::filesystem::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml") << sand_column("E: 5, density: 1.8, phi: 0.52, cc: 1");
  auto r = loam_test::run_loam("run " + (dir.path / "run.yaml").string() + " --out " +
                               (dir.path / "out").string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);  // the one error
  CHECK_THAT(r.output, Contains("error: bodies.0.material.cc: unknown key"));
  std::ofstream(dir.path / "run.yaml") << sand_column("E: 5.0e6, density: 1.8, phi: 30");
  r = loam_test::run_loam("run " + (dir.path / "run.yaml").string() + " --quiet --out " +
                          (dir.path / "out").string());
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.output, !Contains("warning"));
  r = loam_test::run_loam("run " + (dir.path / "run.yaml").string() + " --overwrite --out " +
                          (dir.path / "out").string());
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.output, Contains("warning: bodies.0.material.density"));
}

TEST_CASE("plausibility: a run that would need more than 1e7 steps warns", "[config][cli]") {
  // The sand column's stable step is about 8e-4 s (0.1 m cells, p-wave about 60 m/s): 1e4 s
  // needs about 1.2e7 steps, below time.max_steps (1e8, an error) but above 1e7.
  loam_test::TempDir dir("plausible_steps");
  const std::string sand = sand_column("E: 5.0e6, density: 1800, phi: 30");
  auto r = check(dir, sand, "--set time.end=1e4");
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.output, Contains("warning: time.end: the stable time step at the start is"));
  r = check(dir, sand + "accept_warnings: [time.end]\n", "--set time.end=1e4");
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.output, !Contains("warning"));
  r = check(dir, sand);  // 0.01 s: nothing to say
  CHECK_THAT(r.output, !Contains("warning"));
}

TEST_CASE("plausibility: no shipped run file warns", "[config][unit]") {
  int files = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(std::string(LOAM_SOURCE_DIR) + "/configs")) {
    if (e.path().extension() != ".yaml") continue;
    loam::Diagnostics diag;
    const loam::LoadedConfig cfg = loam::load_config(e.path().string(), {}, diag);
    REQUIRE(diag.ok());
    const loam::RunResult r = loam::check_config(cfg);
    INFO(e.path().string() << "\n" << r.message << r.warnings);
    CHECK(r.exit_code == 0);
    CHECK(r.warnings.empty());
    ++files;
  }
  std::printf("%d shipped run files: no warnings\n", files);
  CHECK(files > 30);
}
