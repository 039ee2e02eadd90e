// The slope scenes (docs/slope_scenes.md): seed 004's large-deformation footing and
// seed 002's frictional and cohesive slopes, measured by the slope_failure reference. The
// papers report descriptions and a few numbers; the tests assert the kind of failure each paper
// describes and print loam's numbers beside the papers'. The quick variants run the same
// configs coarser and shorter; the [full] tests run them as shipped.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;

double num(const nlohmann::json& v, const char* key) {
  return v.contains(key) && v[key].is_number() ? v[key].get<double>() : std::nan("");
}

/// The record of the stage named `name`.
nlohmann::json stage(const nlohmann::json& s, const std::string& name) {
  for (const auto& st : s["stages"])
    if (st["name"] == name) return st;
  FAIL("no stage " << name);
  return {};
}

/// The run went through: status ok and every stage run to its end (the gravity stages static).
void check_ran_through(const nlohmann::json& s) {
  REQUIRE(s["status"] == "ok");
  for (const auto& st : s["stages"]) {
    INFO("stage " << st["name"]);
    CHECK((st["status"] == "static" || st["status"] == "done"));
  }
}

/// Print a slope_failure record beside the paper's numbers.
void print_failure(const char* scene, const nlohmann::json& s) {
  const auto& v = s["verify"];
  std::printf(
      "%s: failed mass %.1f m^2, failure_depth %.2f m, slip_base_height %.2f m, runout %.2f m, "
      "max_displacement %.2f m, time_to_90_percent %.1f s, time_to_rest %.1f s (paper %.0f s), "
      "deposit_top_height %.2f m (paper %.1f m), moved_mass_top_height %.2f m; %ld steps, "
      "%.0f s wall, %.2f M particle-steps/s\n",
      scene, num(v, "failed_volume"), num(v, "failure_depth"), num(v, "slip_base_height"),
      num(v, "runout"), num(v, "max_displacement"), num(v, "time_to_90_percent"),
      num(v, "time_to_rest"), num(v, "paper_time_to_rest"), num(v, "deposit_top_height"),
      num(v, "paper_deposit_top_height"), num(v, "moved_mass_top_height"), s["steps"].get<long>(),
      s["wall_seconds"].get<double>(), s["particle_steps_per_second"].get<double>() / 1e6);
}

}  // namespace

TEST_CASE("seed-004 large-deformation slope, quick variant (1 m cells, 10 s): the strip sinks",
          "[slope][seed004]") {
  // Coarse and short: the gravity stages, then 390 kPa over 3 s and 7 s more. The strip must
  // punch in (deposit_top_height below the crest's 9.5 m) with a failed mass beside it, and
  // the strain_magnitude frame must show the strain under the strip.
  loam_test::TempDir d("seed004_ld_quick");
  const auto s =
      loam_test::run_scene("seed004_slope_large_deformation.yaml", d.path / "out",
                           "--threads 2 --set grid.cell_size=1 --set bodies.0.particles_per_cell=2 "
                           "--set stages.2.duration=10 --set selections.0.min=[4,9.25]");
  print_failure("seed-004 large deformation, quick", s);
  const auto& v = s["verify"];
  check_ran_through(s);
  CHECK(stage(s, "gravity_elastic")["status"] == "static");
  CHECK(stage(s, "gravity_mohr_coulomb")["status"] == "static");
  CHECK(num(v, "failed_volume") > 0);
  CHECK(num(v, "deposit_top_height") < 9.5 - 0.5);
  CHECK(num(v, "deposit_top_height") > 5.0);
}

TEST_CASE("seed-002 slopes, quick variants (1 m cells, 30 s): both fail, the cohesive one deeper",
          "[slope][seed002]") {
  loam_test::TempDir d("seed002_quick");
  // The drop's 20 s stage, then 10 s of its continuation. On 1 m cells the elastic gravity
  // stage still moves at 1.4e-5 m/s after 60 s: the gravity stages count as static at 1e-4 m/s.
  const std::string coarse =
      "--threads 2 --set grid.cell_size=1 --set stages.3.duration=10 "
      "--set stages.0.static_speed=1e-4 --set stages.1.static_speed=1e-4 ";
  const auto fr = loam_test::run_scene("seed002_slope_frictional.yaml", d.path / "fr", coarse);
  print_failure("seed-002 frictional slope, quick", fr);
  const auto co = loam_test::run_scene("seed002_slope_cohesive.yaml", d.path / "co", coarse);
  print_failure("seed-002 cohesive slope, quick", co);
  for (const auto* s : {&fr, &co}) {
    check_ran_through(*s);
    CHECK(num((*s)["verify"], "failed_volume") > 0);
  }
  // The paper: a shallow failure of the frictional slope, a deeper one of the cohesive slope.
  CHECK(num(co["verify"], "failure_depth") > num(fr["verify"], "failure_depth"));
}

TEST_CASE("seed-004 large-deformation slope at the paper's resolution", "[slope][seed004][full]") {
  loam_test::TempDir d("seed004_ld");
  const auto s =
      loam_test::run_scene("seed004_slope_large_deformation.yaml", d.path / "out", "--threads 2");
  print_failure("seed-004 large deformation", s);
  const auto& v = s["verify"];
  check_ran_through(s);
  CHECK(num(v, "failed_volume") > 0);
  // A wedge under the strip and a sliding failure toward the face (Figure 9 of the paper): the
  // strip sinks, the failed mass reaches down the face.
  CHECK(num(v, "deposit_top_height") < 9.5 - 0.5);
  CHECK(num(v, "max_displacement") > 0.5);
  // The snapshots the paper shows, 5, 25, 50, 75 and 100 s after the load began, are frames.
  const double t0 = stage(s, "load_390kPa")["start_time"].get<double>();
  const std::string xdmf = loam_test::slurp(d.path / "out" / "particles.xdmf");
  for (double t : {5.0, 25.0, 50.0, 75.0, 100.0}) {
    bool found = false;
    for (size_t at = xdmf.find("Time Value=\""); at != std::string::npos;
         at = xdmf.find("Time Value=\"", at + 1))
      found = found || std::abs(std::stod(xdmf.substr(at + 12)) - (t0 + t)) < 0.01;
    INFO("a frame " << t << " s after the load began");
    CHECK(found);
  }
}

TEST_CASE("seed-002 frictional and cohesive slopes as shipped", "[slope][seed002][full]") {
  loam_test::TempDir d("seed002");
  const auto fr =
      loam_test::run_scene("seed002_slope_frictional.yaml", d.path / "fr", "--threads 2");
  print_failure("seed-002 frictional slope", fr);
  const auto co = loam_test::run_scene("seed002_slope_cohesive.yaml", d.path / "co", "--threads 2");
  print_failure("seed-002 cohesive slope", co);
  for (const auto* s : {&fr, &co}) {
    check_ran_through(*s);
    CHECK(num((*s)["verify"], "failed_volume") > 0);
  }
  // Shallow against deep (the paper's Figure 7b, 7c).
  CHECK(num(co["verify"], "failure_depth") > num(fr["verify"], "failure_depth"));
  // The frictional slide does most of its movement early (the paper: in the first 50 s).
  CHECK(num(fr["verify"], "time_to_90_percent") < 50);
}
