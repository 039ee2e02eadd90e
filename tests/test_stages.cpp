// Staged analysis (issue 15, docs/stages.md): a run with one explicit stage is bitwise the plain
// run of the same time; a load added by a stage acts from exactly the stage's start; bad stage
// input gives located errors, exit 2, and no output.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;

/// A 1D elastic column 1 m tall on a fixed base, 0.1 m cells, 2 particles per cell, no gravity:
/// at rest until something loads it.
std::string column(const std::string& time_and_stages) {
  return "grid: {extent: [1.2], cell_size: 0.1}\n"
         "bodies:\n"
         "  - name: soil\n"
         "    generator: {type: box, min: [0], max: [1]}\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0, density: 1000}\n"
         "selections:\n"
         "  - {name: top, min: [0.9], max: [1]}\n"
         "boundaries:\n"
         "  - {type: fixed, face: x-}\n"
         "output: {every_steps: 20, fields: [velocity, stress]}\n"
         "probes:\n"
         "  - {name: tip, particle_near: [0.975], fields: [velocity]}\n" +
         time_and_stages;
}

}  // namespace

TEST_CASE("one explicit stage is bitwise the plain run of the same time", "[stages]") {
  const std::string load =
      "loads: [{type: traction, selection: top, face: x+, traction: [-1000]}]\n";
  loam_test::TempDir a("stage_plain"), b("stage_one");
  auto ra = loam_test::run_yaml(a.path, column(load + "time: {end: 0.05}\n"), "--threads 1");
  auto rb = loam_test::run_yaml(b.path,
                                column(load + "stages:\n"
                                              "  - {name: all, duration: 0.05}\n"),
                                "--threads 1");
  INFO(ra.output << rb.output);
  REQUIRE(ra.exit_code == 0);
  REQUIRE(rb.exit_code == 0);
  long frames = 0;
  for (const auto& e : fs::directory_iterator(a.path / "out")) {
    if (e.path().extension() != ".h5") continue;
    const auto other = b.path / "out" / e.path().filename();
    REQUIRE(fs::exists(other));
    ++frames;
    for (const char* f : {"position", "velocity", "stress"})
      CHECK(loam_test::read_frame_doubles(e.path(), f) == loam_test::read_frame_doubles(other, f));
  }
  std::printf("one explicit stage against the plain run: %ld frames compared bitwise\n", frames);
  CHECK(frames >= 2);
  CHECK(loam_test::slurp(a.path / "out" / "probe_tip.csv") ==
        loam_test::slurp(b.path / "out" / "probe_tip.csv"));
  auto s = nlohmann::json::parse(loam_test::slurp(b.path / "out" / "summary.json"));
  REQUIRE(s["stages"].size() == 1);
  CHECK(s["stages"][0]["status"] == "done");
}

TEST_CASE("a load added by a stage acts from exactly the stage's start", "[stages]") {
  // Stage 1 (0.02 s) has no load: the column stays exactly at rest (velocity 0.0, not round-off).
  // Stage 2 adds the traction: the tip moves from its first step on.
  loam_test::TempDir d("stage_load");
  auto r = loam_test::run_yaml(
      d.path,
      column("stages:\n"
             "  - {name: rest, duration: 0.02}\n"
             "  - name: load\n"
             "    duration: 0.02\n"
             "    loads: [{type: traction, selection: top, face: x+, traction: [-1000]}]\n"),
      "--threads 1");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  auto p = loam_test::read_csv_columns(d.path / "out" / "probe_tip.csv");
  REQUIRE(p.count("time"));
  REQUIRE(p.count("velocity"));
  const auto& t = p["time"];
  const auto& v = p["velocity"];
  size_t before = 0, after = 0;
  double first_after = 0;
  for (size_t i = 0; i < t.size(); ++i) {
    if (t[i] <= 0.02 * (1 + 1e-12)) {
      ++before;
      CHECK(v[i] == 0.0);
    } else if (after++ == 0) {
      first_after = v[i];
    }
  }
  std::printf("stage load: %zu samples at rest before t = 0.02 s, first velocity after %.3e m/s\n",
              before, first_after);
  CHECK(before > 5);
  CHECK(after > 5);
  CHECK(first_after < 0.0);  // pushed down (towards x-)
  auto s = nlohmann::json::parse(loam_test::slurp(d.path / "out" / "summary.json"));
  REQUIRE(s["stages"].size() == 2);
  CHECK(s["stages"][1]["start_time"].get<double>() == Approx(0.02).margin(1e-12));
}

TEST_CASE("bad stage input: located errors, all at once, exit 2, no output",
          "[stages][bad_config]") {
  loam_test::TempDir d("stage_bad");
  const std::string yaml = column(
      "stages:\n"
      "  - name: a\n"
      "    duration: -1\n"  // line 15
      "  - name: b\n"
      "    until: static\n"  // line 17: no max_time
      "  - name: c\n"
      "    duration: 1\n"
      "    activate: [soil]\n"  // active from the start
      "    materials: [{body: sand, material: {type: linear_elastic, E: 1, nu: 0, density: 1}}]\n"
      "  - name: d\n"
      "    duration: 1\n"
      "    materials: [{body: soil, material: {E: 2.0e6, phy: 3}}]\n");  // line 24
  auto r = loam_test::run_yaml(d.path, yaml);
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK_FALSE(fs::exists(d.path / "out"));
  const std::string f = (d.path / "run.yaml").string();
  for (const std::string& e :
       {f + ":15:15: error: stages.0.duration: -1 is out of range (0, inf) s",
        f + ":17:12: error: stages.1.until: until: static needs max_time",
        f + ":24:51: error: stages.3.materials.0.material.phy: unknown key 'phy'"}) {
    INFO(e);
    CHECK(r.output.find(e) != std::string::npos);
  }
  // Errors found once the bodies are known (reported together when the schema passes).
  auto r2 = loam_test::run_yaml(
      d.path, column("stages:\n"
                     "  - name: c\n"
                     "    duration: 1\n"
                     "    activate: [soil]\n"
                     "    materials: [{body: sand, material: {type: linear_elastic, E: 1, nu: 0, "
                     "density: 1}}]\n"));
  INFO(r2.output);
  CHECK(r2.exit_code == 2);
  CHECK_FALSE(fs::exists(d.path / "out"));
  CHECK(r2.output.find("error: stages.0.activate.0: body 'soil' is in the run from the start") !=
        std::string::npos);
  CHECK(r2.output.find("error: stages.0.materials.0.body: unknown body 'sand'; bodies are: soil") !=
        std::string::npos);
}
