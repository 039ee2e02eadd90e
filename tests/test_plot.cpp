// `loam plot RUN`: one figure of any run (tools/loam_plot.py) with the interpreter loam calls,
// for every shipped scene, and located messages for what a run does not have.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>

#include "cli.hpp"

namespace fs = std::filesystem;
using loam_test::run_loam;
using loam_test::slurp;
using loam_test::TempDir;

namespace {

/// The --set overrides that make a shipped scene's quick variant: a few milliseconds of its
/// physics with two frames (a staged scene: one short stage; strength reduction: trials as short).
std::string quick_variant(const fs::path& config) {
  const std::string text = slurp(config);
  std::string sets = " --set output.every_time=0.001";
  if (text.find("\nstrength_reduction:") != std::string::npos)
    return sets + " --set 'stages=[{name: quick, until: static, max_time: 0.002}]'" +
           " --set strength_reduction.max_time=0.002";
  if (text.find("\nstages:") != std::string::npos)
    return sets + " --set 'stages=[{name: quick, duration: 0.002}]'";
  return sets + " --set time.end=0.002";
}

std::vector<fs::path> shipped_scenes() {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(LOAM_SOURCE_DIR) / "configs"))
    if (e.path().extension() == ".yaml") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

/// Runs the quick variant of every other shipped scene (from `first`) and plots it.
void plot_every_other_scene(size_t first) {
  TempDir dir("plot_scenes");
  const auto files = shipped_scenes();
  REQUIRE(files.size() > 30);
  for (size_t i = first; i < files.size(); i += 2) {
    const fs::path out = dir.path / files[i].stem();
    const auto run = run_loam("run " + files[i].string() + " --quiet --threads 1 --out " +
                              out.string() + quick_variant(files[i]));
    INFO(files[i].filename().string() << ": " << run.output);
    REQUIRE(run.exit_code == 0);
    const auto plot = run_loam("plot " + out.string());
    INFO(plot.output);
    CHECK(plot.exit_code == 0);
    const std::string png = slurp(out / "plot.png");
    CHECK(png.size() > 10000);
    CHECK(png.compare(0, 4, "\x89PNG") == 0);
  }
}

}  // namespace

TEST_CASE("loam plot draws every shipped scene's quick variant (first half)", "[plot]") {
  plot_every_other_scene(0);
}

TEST_CASE("loam plot draws every shipped scene's quick variant (second half)", "[plot]") {
  plot_every_other_scene(1);
}

TEST_CASE("loam plot: a field, a frame and a set the run does not have are errors", "[plot]") {
  TempDir dir("plot_errors");
  const fs::path out = dir.path / "run";
  const auto run = run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                            "/configs/hydrostatic_double_point.yaml --quiet --threads 1 --out " +
                            out.string() + " --set time.end=0.002 --set output.every_time=0.001");
  REQUIRE(run.exit_code == 0);
  struct Case {
    std::string args, message;
  };
  const std::vector<Case> cases = {
      {"--field nope", "--field nope: set liquid: no nope (it has"},
      {"--field stress:9", "--field stress:9: set liquid: stress has components 0 to 2"},
      {"--frame 7", "--frame 7: set liquid has frames 0 to 2 (or -1 to -3 from the last)"},
      {"--set gas", "--set gas: the run's sets are liquid, solid"},
  };
  for (const auto& c : cases) {
    const auto r = run_loam("plot " + out.string() + " " + c.args);
    INFO(c.args << ": " << r.output);
    CHECK(r.exit_code == 2);
    CHECK_THAT(r.output, Catch::Matchers::Contains("loam plot: error: " + c.message));
  }
  CHECK_FALSE(fs::exists(out / "plot.png"));
  const auto none = run_loam("plot " + (dir.path / "nowhere").string());
  CHECK(none.exit_code == 2);
  CHECK_THAT(none.output, Catch::Matchers::Contains("no such run directory"));
  // A field of one set only: the other set is drawn in grey, the figure is written.
  const auto p = run_loam("plot " + out.string() + " --field pore_pressure --frame 0");
  INFO(p.output);
  CHECK(p.exit_code == 0);
  CHECK(fs::exists(out / "plot.png"));
}
