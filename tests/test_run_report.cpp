// The end of `loam run` (framework/run_report.hpp, docs/runs.md "What a run tells"): where the
// output went, the status, each comparison of the reference beside the value it is compared
// with, the other error metrics, every stage's outcome and the factor of safety; --quiet keeps
// it to one line.
#include <algorithm>
#include <catch2/catch.hpp>
#include <fstream>

#include "cli.hpp"
#include "framework/run_report.hpp"

using Catch::Matchers::Contains;
using nlohmann::json;

namespace {

std::string joined(const std::vector<std::string>& lines) {
  std::string s;
  for (const auto& l : lines) s += l + "\n";
  return s;
}

json staged_summary(int stages) {
  json s = {{"status", "ok"}, {"steps", 1200}, {"wall_seconds", 3.5}};
  s["verify"] = {{"reference", "settlement"},
                 {"final_settlement", 0.0105},
                 {"expected_settlement", 0.01},
                 {"settlement_error", 0.05},
                 {"max_error", 0.02}};
  s["verify"]["comparisons"].push_back({{"measured", "final_settlement"},
                                        {"value", 0.0105},
                                        {"reference", "expected_settlement"},
                                        {"reference_value", 0.01},
                                        {"source", "oedometer"}});
  for (int k = 0; k < stages; ++k)
    s["stages"].push_back({{"name", "load_" + std::to_string(k)},
                           {"status", k + 1 < stages ? "static" : "not_static"},
                           {"end_time", 1.5 * (k + 1)}});
  return s;
}

}  // namespace

TEST_CASE("run report: comparisons with their difference, other errors, every stage",
          "[output][unit]") {
  const json s = staged_summary(30);
  const auto lines = loam::run_report(s, "results/x");
  const std::string text = joined(lines);
  std::printf("%s", text.c_str());
  CHECK_THAT(lines[0], Contains("status ok") && Contains("results/x"));
  CHECK_THAT(text, Contains("final_settlement 0.0105 against 0.01 (oedometer), +5 %"));
  // settlement_error is not in a comparison's measured key: listed with the other errors
  CHECK_THAT(text, Contains("settlement_error 0.05") && Contains("max_error 0.02"));
  // 29 static stages then one not static: one group and the last stage by name
  CHECK_THAT(text, Contains("stages: load_0 ... load_28 static (29 stages, to 43.5 s); load_29 "
                            "not_static at 45 s"));
  CHECK(lines.size() <= 5);  // a few lines, not one per stage
  json alternating = staged_summary(4);
  alternating["stages"][1]["status"] = "not_static";
  const std::string each = joined(loam::run_report(alternating, "results/x"));
  for (const char* item : {"load_0 static at 1.5 s", "load_1 not_static at 3 s",
                           "load_2 static at 4.5 s", "load_3 not_static at 6 s"})
    CHECK_THAT(each, Contains(item));
}

TEST_CASE("run report: strength reduction and a run without output or reference",
          "[output][unit]") {
  json s = {{"status", "ok"}, {"steps", 10}, {"wall_seconds", 1.0}, {"verify", json::object()}};
  s["strength_reduction"] = {{"status", "converged"},
                             {"factor_of_safety", 1.5813},
                             {"factor_of_safety_bracket", {1.575, 1.5875}}};
  s["factor_of_safety"] = 1.5813;
  const std::string text = joined(loam::run_report(s, ""));
  std::printf("%s", text.c_str());
  CHECK_THAT(text, Contains("no output written"));
  CHECK_THAT(text, Contains("converged, factor of safety 1.581 [1.575, 1.5875]"));
  const std::string line = loam::run_report_line(s, "");
  CHECK(line.find('\n') == std::string::npos);
  CHECK_THAT(line, Contains("factor of safety 1.581"));
  s["strength_reduction"] = {{"status", "above_bracket"},
                             {"factor_of_safety_bracket", {2.0, nullptr}}};
  CHECK_THAT(joined(loam::run_report(s, "out")), Contains("above_bracket [2, -]"));
  s["strength_reduction"] = {{"status", "undecided"},
                             {"factor_of_safety", 1.5813},
                             {"factor_of_safety_bracket", {1.575, 1.5875}},
                             {"undecided_factor", 1.5875}};
  CHECK_THAT(joined(loam::run_report(s, "out")),
             Contains("undecided, factor of safety 1.581 [1.575, 1.5875] (the trial F = 1.5875 "
                      "was still moving at max_time)"));
}

TEST_CASE("loam run ends by telling its output, status and the reference's comparison",
          "[output][cli]") {
  // configs/granular_collapse_2d.yaml for 0.05 s: the run-out and height ratios against Lube
  // et al. (2005) as summary.json has them.
  loam_test::TempDir dir("run_report");
  const std::string args = std::string("run ") + LOAM_SOURCE_DIR +
                           "/configs/granular_collapse_2d.yaml --threads 1 --set time.end=0.05 "
                           "--overwrite --out " +
                           (dir.path / "out").string();
  const auto full = loam_test::run_loam(args);
  std::printf("%s", full.output.c_str());
  REQUIRE(full.exit_code == 0);
  json s;
  std::ifstream(dir.path / "out" / "summary.json") >> s;
  const json& c = s["verify"]["comparisons"];
  REQUIRE(c.size() == 2);
  CHECK(c[0]["measured"] == "runout_ratio");
  CHECK(c[0]["value"] == s["verify"]["runout_ratio"]);
  CHECK(c[0]["reference_value"] == s["verify"]["lube2005_runout_ratio"]);
  CHECK_THAT(full.output, Contains("output in " + (dir.path / "out").string()));
  CHECK_THAT(full.output, Contains("runout_ratio") && Contains("(Lube et al. 2005)"));
  const auto quiet = loam_test::run_loam(args + " --quiet");
  std::printf("%s", quiet.output.c_str());
  REQUIRE(quiet.exit_code == 0);
  CHECK(std::count(quiet.output.begin(), quiet.output.end(), '\n') == 1);
  CHECK_THAT(quiet.output,
             Contains((dir.path / "out").string() + ": ok,") && Contains("height_ratio"));
}
