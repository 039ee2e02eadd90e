// Seed 002's blasting problem (configs/seed002_blast_3d.yaml,
// docs/blast.md): a pressure pulse in a borehole in granite under sand, a quarter model with
// absorbing far faces. The blast_wave reference compares first-break arrival times at the probes
// with the layers' P-wave speeds (Fermat rays, docs/verification.md H) and records peak
// displacements, p-q paths and failure. The quick variant runs the config on 2 m cells; the
// [full] test as shipped (1 m cells).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "cli.hpp"

namespace {

double num(const nlohmann::json& v, const std::string& key) {
  return v.contains(key) && v[key].is_number() ? v[key].get<double>() : std::nan("");
}

/// Print the probes' arrivals and peaks; return the summary's verify block.
nlohmann::json report(const char* variant, const nlohmann::json& s) {
  const auto& v = s["verify"];
  for (const char* p : {"P1", "P2", "P3", "S1", "S2"}) {
    const std::string n(p);
    std::printf(
        "blast %s %s: arrival %.3f ms (Fermat %.3f ms, %+.1f %%), peak displacement "
        "%.2e m, peak speed %.2e m/s, failed %g\n",
        variant, p, 1e3 * num(v, "arrival_time_" + n), 1e3 * num(v, "expected_arrival_" + n),
        100 * num(v, "arrival_error_" + n), num(v, "peak_displacement_" + n),
        num(v, "peak_speed_" + n), num(v, "failed_" + n));
  }
  std::printf(
      "blast %s: arrival_time_error %.3f (granite probes), %.3f (sand probes); %ld steps, "
      "%ld particles, %.0f s wall, %.2f M particle-steps/s\n",
      variant, num(v, "arrival_time_error"), num(v, "arrival_time_error_cover"),
      s["steps"].get<long>(), s["particles"].get<long>(), s["wall_seconds"].get<double>(),
      s["particle_steps_per_second"].get<double>() / 1e6);
  return v;
}

/// What both resolutions must show besides the arrival times.
void check_blast(const nlohmann::json& s) {
  REQUIRE(s["status"] == "ok");
  const auto& v = s["verify"];
  // c_p = sqrt(M / rho) from Table 1: granite 2411.2 m/s, sand 251.38 m/s (docs/verification.md H).
  CHECK(num(v, "p_wave_speed_body") == Approx(2411.2).epsilon(1e-4));
  CHECK(num(v, "p_wave_speed_cover") == Approx(251.38).epsilon(1e-4));
  // Geometric spreading: the farther probe moves less.
  CHECK(num(v, "peak_displacement_P1") > num(v, "peak_displacement_P2"));
  CHECK(num(v, "peak_displacement_P2") > num(v, "peak_displacement_P3"));
  // The paper's order of magnitude (1e-4 m) for the equivalent 0.05 m hole (docs/blast.md).
  CHECK(num(v, "peak_displacement") > 1e-5);
  CHECK(num(v, "peak_displacement") < 1e-3);
}

}  // namespace

TEST_CASE("seed-002 blast, quick variant (2 m cells): first breaks at the granite's P-wave speed",
          "[blast][seed002]") {
  // 2 m cells (216 000 particles, 145 steps to 0.06 s). P1 lies 4.5 cells from the wall, so the
  // front's smear over about a cell weighs 10-20 % there; target: every granite probe within
  // 10 % of its Fermat arrival (measured 7 % at P2). The [full] test holds 5 % on 1 m cells.
  loam_test::TempDir d("blast_quick");
  const auto s = loam_test::run_scene("seed002_blast_3d.yaml", d.path / "out",
                                      "--threads 2 --set grid.cell_size=2");
  const auto v = report("2 m cells", s);
  check_blast(s);
  CHECK(num(v, "arrival_time_error") < 0.10);
}

TEST_CASE("seed-002 blast as shipped (1 m cells): first breaks within 5 % in the granite",
          "[blast][seed002][full]") {
  loam_test::TempDir d("blast_full");
  const auto s = loam_test::run_scene("seed002_blast_3d.yaml", d.path / "out", "--threads 2");
  const auto v = report("1 m cells", s);
  check_blast(s);
  CHECK(num(v, "arrival_time_error") < 0.05);
  CHECK(s["wall_seconds"].get<double>() < 20 * 60);
}
