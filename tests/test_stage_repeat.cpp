// Repeated stages (framework/stage_repeat.hpp, docs/stages.md "Repeated stages"): a stage with
// `repeat: {times: N, step: {key.path: increment}}` is N copies of it, each stepped value
// v + k * increment. The run of a repeated stage must be the run of the copied stages to the bit;
// a bad repeat is a located error.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "cli.hpp"
#include "framework/config.hpp"

using Catch::Matchers::Contains;

namespace {

/// A 1D elastic column under gravity (fixed base, local damping) that settles, then carries a
/// traction on its top raised by 20 kPa per stage: `load_stages` is the stages' text after the
/// settle.
std::string column(const std::string& load_stages) {
  return "grid: {origin: [0], extent: [1.2], cell_size: 0.1}\n"
         "gravity: [-9.81]\n"
         "bodies:\n"
         "  - {name: soil, generator: {type: box, min: [0], max: [1]},\n"
         "     material: {type: linear_elastic, E: 1.0e7, nu: 0, density: 2000}}\n"
         "boundaries: [{type: fixed, face: x-}]\n"
         "damping: {type: local, alpha: 0.7}\n"
         "output: {every_time: 0.05, fields: [velocity, stress, displacement]}\n"
         "stages:\n"
         "  - {name: settle, until: static, max_time: 1}\n" +
         load_stages;
}

std::string explicit_loads() {
  std::string s;
  for (int k = 0; k < 3; ++k)
    s += "  - {name: load_" + std::to_string(k + 1) +
         ", until: static, max_time: 1, loads: [{type: traction, body: soil, face: x+, "
         "traction: [" +
         std::to_string(-20000 * (k + 1)) + "]}]}\n";
  return s;
}

const std::string kRepeatedLoads =
    "  - name: load\n"
    "    until: static\n"
    "    max_time: 1\n"
    "    loads: [{type: traction, body: soil, face: x+, traction: [-20000]}]\n"
    "    repeat: {times: 3, step: {loads.0.traction: [-20000]}}\n";

}  // namespace

TEST_CASE("repeat: a repeated stage runs as its copies, to the bit", "[stages][cli]") {
  loam_test::TempDir dir("stage_repeat");
  const auto copied =
      loam_test::run_yaml(dir.path / "copied", column(explicit_loads()), "--threads 1");
  const auto repeated =
      loam_test::run_yaml(dir.path / "repeated", column(kRepeatedLoads), "--threads 1");
  REQUIRE(copied.exit_code == 0);
  REQUIRE(repeated.exit_code == 0);
  const auto a = nlohmann::json::parse(loam_test::slurp(dir.path / "copied/out/summary.json"));
  const auto b = nlohmann::json::parse(loam_test::slurp(dir.path / "repeated/out/summary.json"));
  REQUIRE(a["stages"].size() == 4);
  REQUIRE(b["stages"].size() == 4);
  for (size_t k = 0; k < 4; ++k) {
    std::printf(
        "%s: %s at %.6f s | %s: %s at %.6f s\n", a["stages"][k]["name"].get<std::string>().c_str(),
        a["stages"][k]["status"].get<std::string>().c_str(),
        a["stages"][k]["end_time"].get<double>(), b["stages"][k]["name"].get<std::string>().c_str(),
        b["stages"][k]["status"].get<std::string>().c_str(),
        b["stages"][k]["end_time"].get<double>());
    CHECK(a["stages"][k]["name"] == b["stages"][k]["name"]);  // load_1 .. load_3
    CHECK(a["stages"][k]["end_time"] == b["stages"][k]["end_time"]);
    CHECK(a["stages"][k]["max_displacement"] == b["stages"][k]["max_displacement"]);
  }
  CHECK(a["stages"][3]["status"] == "static");
  CHECK(a["steps"] == b["steps"]);
  CHECK(loam_test::slurp(dir.path / "copied/out/history.csv") ==
        loam_test::slurp(dir.path / "repeated/out/history.csv"));
  const auto last = "particles_" +
                    std::string(6 - std::to_string(a["frames"].get<int>() - 1).size(), '0') +
                    std::to_string(a["frames"].get<int>() - 1) + ".h5";
  for (const char* field : {"position", "stress", "displacement"})
    CHECK(loam_test::read_frame_doubles(dir.path / "copied/out" / last, field) ==
          loam_test::read_frame_doubles(dir.path / "repeated/out" / last, field));
}

TEST_CASE("repeat: the shipped staged footing is its 30 load stages", "[stages][unit]") {
  // configs/seed004_slope_staged.yaml loads the strip in 15 kPa steps to 450 kPa: its load
  // stages after the first (load_15kPa, which resets the displacement) come from one repeated
  // stage, load_1 .. load_29 at 30 .. 450 kPa. The expanded stages must be those copies.
  loam::Diagnostics diag;
  const auto cfg = loam::load_config(
      std::string(LOAM_SOURCE_DIR) + "/configs/seed004_slope_staged.yaml", {}, diag);
  REQUIRE(diag.ok());
  const auto& stages = cfg.params.list("stages");
  REQUIRE(stages.size() == 32);
  for (int k = 1; k <= 29; ++k) {
    const loam::Params& st = stages[size_t(2 + k)];
    CHECK(st.text("name") == "load_" + std::to_string(k));
    CHECK(st.text("until") == "static");
    CHECK(st.real("max_time") == 10);
    CHECK(st.list("loads").size() == 1);
    CHECK(st.list("loads")[0].vec("traction") == std::vector<double>{0, -15000.0 * (k + 1)});
    CHECK(st.strings("reset").empty());
  }
}

TEST_CASE("repeat: a bad repeat is a located error", "[stages][cli]") {
  loam_test::TempDir dir("stage_repeat_bad");
  struct Case {
    std::string repeat, location, message;
  };
  for (const Case& c :
       {Case{"{times: 0, step: {loads.0.traction: [-20000]}}",
             ":15:21:", "stages.1.repeat.times: expected the number of copies"},
        Case{"{times: 2, step: {loads.0.force: [-20000]}}", ":15:31:",
             "stages.1.repeat.step.loads.0.force: the stage has no value at 'loads.0.force'"},
        Case{"{times: 2, step: {loads.0.traction: [-1, 2]}}",
             ":15:49:", "stages.1.repeat.step.loads.0.traction: the increment must have the shape"},
        Case{"{times: 2, every: 3}", ":15:24:", "stages.1.repeat.every: unknown key"}}) {
    std::string yaml = column(kRepeatedLoads);
    const std::string old = "{times: 3, step: {loads.0.traction: [-20000]}}";
    yaml.replace(yaml.find(old), old.size(), c.repeat);
    const auto r = loam_test::run_yaml(dir.path, yaml);
    std::printf("%s", r.output.c_str());
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.output, Contains("run.yaml" + c.location) && Contains(c.message));
    CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
  }
}
