// Run contract: output files, probes, the unstable-run stop (exit 3), overrides in the summary.
#include <catch2/catch.hpp>
#include <fstream>
#include <regex>
#include <sstream>

#include "cli.hpp"

using loam_test::run_loam;
using loam_test::slurp;
using loam_test::TempDir;

TEST_CASE("a run writes XDMF frames, probes, history and a complete summary", "[output]") {
  TempDir dir("output");
  auto r =
      run_loam(std::string("run ") + LOAM_SOURCE_DIR +
               "/configs/vibrating_bar.yaml --quiet --set time.end=20 --out " + dir.path.string());
  REQUIRE(r.exit_code == 0);
  auto s = nlohmann::json::parse(slurp(dir.path / "summary.json"));
  for (const char* key :
       {"loam_version", "git_commit", "config", "dimension", "particles", "cells", "steps",
        "end_time", "wall_seconds", "threads", "particle_steps_per_second", "verify"})
    CHECK(s.contains(key));
  CHECK(s["config"]["time"]["end"].get<double>() == 20.0);  // echo after overrides
  CHECK(s["config"]["scheme"]["update"] == "musl");         // and with defaults filled in
  CHECK(s["end_time"].get<double>() == Approx(20.0));
  // Frames every 1 s for 20 s, plus t = 0.
  std::string xdmf = slurp(dir.path / "particles.xdmf");
  size_t frames = 0;
  for (size_t pos = 0; (pos = xdmf.find("<Time Value", pos)) != std::string::npos; ++pos) ++frames;
  CHECK(frames == 21);
  CHECK(std::filesystem::exists(dir.path / "particles_000020.h5"));
  // The tip probe samples every step: a header plus steps + 1 rows.
  std::ifstream probe(dir.path / "probe_tip.csv");
  std::string header, line;
  std::getline(probe, header);
  CHECK(header == "step,time,position,velocity,displacement,stress_xx,stress_yy,stress_zz");
  long rows = 0;
  while (std::getline(probe, line)) ++rows;
  CHECK(rows == s["steps"].get<long>() + 1);
  // No temporary files are left behind.
  for (const auto& e : std::filesystem::directory_iterator(dir.path))
    CHECK(e.path().extension() != ".tmp");
  // A run without a reference still has verify: an empty map (the agreed field list).
  TempDir plain("output_plain");
  auto p = run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                    "/configs/vibrating_bar.yaml --quiet --set time.end=0.5 --set "
                    "'verify=null' --out " + plain.path.string());
  std::printf("%s", p.output.c_str());
  REQUIRE(p.exit_code == 0);
  auto q = nlohmann::json::parse(slurp(plain.path / "summary.json"));
  REQUIRE(q.contains("verify"));
  CHECK(q["verify"].is_object());
  CHECK(q["verify"].empty());
}

TEST_CASE("an unstable run stops with exit 3 naming step, time, particle and field", "[output]") {
  // A fixed time step 100x above the CFL limit makes the column explode.
  TempDir dir("unstable");
  auto r = run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                    "/configs/elastic_column_1d.yaml --quiet --set time.dt=0.01 --out " +
                    dir.path.string());
  INFO(r.output);
  CHECK(r.exit_code == 3);
  std::regex pattern(
      R"(loam: error: unstable run at step \d+, t = [0-9.e+-]+ s: particle \d+ \(body 'column'\): (position|velocity|stress)\S* .*)");
  CHECK(std::regex_search(r.output, pattern));
  auto s = nlohmann::json::parse(slurp(dir.path / "summary.json"));
  CHECK(s["status"] == "unstable");
  bool failed_frame = false;
  for (const auto& e : std::filesystem::directory_iterator(dir.path))
    failed_frame =
        failed_frame || e.path().filename().string().find("_failed.h5") != std::string::npos;
  CHECK(failed_frame);
}

TEST_CASE("loam check validates without writing, plugins lists every kind", "[output]") {
  auto r = run_loam(std::string("check ") + LOAM_SOURCE_DIR + "/configs/elastic_column_3d.yaml");
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("ok (3D, 5120 particles, 672 cells)") != std::string::npos);
  auto p = run_loam("plugins");
  CHECK(p.exit_code == 0);
  for (const char* kind : {"shape_function", "material", "scheme", "boundary", "load", "damping",
                           "reference", "writer"})
    CHECK(p.output.find(std::string(kind) + " — ") != std::string::npos);
  CHECK(p.output.find("E  (real, Pa, required, range (0, inf))") != std::string::npos);
  auto bad = run_loam("plugins materail");
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("did you mean 'material'?") != std::string::npos);
}

TEST_CASE("a plugin given by name only can have its parameters overridden with --set", "[output]") {
  // `shape_function: linear` is shorthand for {type: linear}; `--set shape_function.key=...`
  // used to abort inside yaml-cpp.
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/vibrating_bar.yaml";
  auto ok = run_loam("check " + cfg + " --set scheme=single_phase --set scheme.update=usl");
  CHECK(ok.exit_code == 0);
  auto bad = run_loam("check " + cfg + " --set shape_function=linear --set shape_function.foo=1");
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("<--set shape_function=linear>:1:1: error: shape_function.foo: unknown key "
                        "'foo' (this takes no parameters)") != std::string::npos);
}

TEST_CASE("a collapsing time step stops the run early with the cause (time.min_dt_ratio)",
          "[output]") {
  // USL with linear hats on a rigidly translating block: once the leading particle passes
  // within round-off of a cell face, the node ahead has a tiny mass and f/m feeds back into the
  // stress (tests/test_invariance.cpp skips this pair for that reason); the stable step fell to
  // 1e-156 s and the run crawled on to the 1e8-step budget. It must stop when dt falls below
  // 1e-6 of the first step's (default), naming the cause, with exit code 3, within the ~100
  // steps the blow-up takes.
  TempDir dir("dt_collapse");
  std::filesystem::create_directories(dir.path);
  std::ofstream(dir.path / "block.yaml")
      << "grid: {origin: [0], extent: [2.0], cell_size: 0.05}\n"
         "scheme: {type: single_phase, update: usl}\n"
         "bodies:\n"
         "  - {name: block, generator: {type: box, min: [0.5], max: [1.0]}, particles_per_cell: "
         "2,\n"
         "     material: {type: linear_elastic, E: 1.0e7, nu: 0.0, density: 2650}, velocity: "
         "[0.5]}\n"
         "time: {end: 0.2, cfl: 0.5}\n";
  auto r = run_loam("run " + (dir.path / "block.yaml").string() + " --quiet --out " +
                    (dir.path / "out").string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 3);
  CHECK(r.output.find("the stable time step collapsed to") != std::string::npos);
  CHECK(r.output.find("below time.min_dt_ratio = 1e-06 of the first step's") != std::string::npos);
  auto s = nlohmann::json::parse(slurp(dir.path / "out" / "summary.json"));
  CHECK(s["status"] == "unstable");
  CHECK(s["steps"].get<long>() < 1000);
}
