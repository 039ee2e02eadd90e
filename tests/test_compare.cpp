// `loam compare`: every combination runs, failures are rows, finished variants are not re-run.
#include <catch2/catch.hpp>
#include <fstream>
#include <sstream>

#include "cli.hpp"

using loam_test::run_loam;
using loam_test::TempDir;

namespace {

std::vector<std::vector<std::string>> read_csv(const std::filesystem::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::ifstream in(p);
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (char c : line) {
      if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted)
        cells.push_back(cell), cell.clear();
      else
        cell += c;
    }
    cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

}  // namespace

TEST_CASE("loam compare runs a sweep, records failures as rows and resumes", "[compare]") {
  TempDir dir("compare");
  std::filesystem::create_directories(dir.path);
  const auto sweep = dir.path / "sweep.yaml";
  std::ofstream(sweep) << "base: " << LOAM_SOURCE_DIR << "/configs/vibrating_bar.yaml\n"
                       << "set: [time.end=30]\n"
                       << "axes:\n"
                       << "  grid.cell_size: [1.0, 0.5]\n"
                       << "  time.dt: [0.01, 1.0]\n"  // 1.0 s is far above the CFL limit
                       << "metric: period_error\nthreads: 1\n";
  const auto out = dir.path / "out";
  auto r = run_loam("compare " + sweep.string() + " --out " + out.string());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  auto rows = read_csv(out / "compare.csv");
  REQUIRE(rows.size() == 5);  // header + 2 x 2 variants
  const auto& h = rows[0];
  auto col = [&](const std::string& name) {
    return size_t(std::find(h.begin(), h.end(), name) - h.begin());
  };
  for (const char* c : {"grid.cell_size", "time.dt", "status", "wall_seconds",
                        "particle_steps_per_second", "period_error", "energy_drift", "message"})
    CHECK(col(c) < h.size());
  int ok = 0, unstable = 0;
  for (size_t i = 1; i < rows.size(); ++i) {
    const auto& row = rows[i];
    if (row[col("time.dt")] == "0.01") {
      CHECK(row[col("status")] == "ok");
      CHECK(std::stod(row[col("period_error")]) < 0.01);
      ++ok;
    } else {
      CHECK(row[col("status")] == "unstable");
      CHECK(row[col("message")].find("unstable run at step") != std::string::npos);
      ++unstable;
    }
  }
  CHECK(ok == 2);
  CHECK(unstable == 2);
  // Re-running skips every finished variant (ok and failed alike).
  auto again = run_loam("compare " + sweep.string() + " --out " + out.string());
  CHECK(again.exit_code == 0);
  size_t skipped = 0;
  for (size_t pos = 0; (pos = again.output.find("already done", pos)) != std::string::npos; ++pos)
    ++skipped;
  CHECK(skipped == 4);
  CHECK(read_csv(out / "compare.csv").size() == 5);
}

TEST_CASE("loam compare rejects a bad sweep file with a located error", "[compare]") {
  TempDir dir("compare_bad");
  std::filesystem::create_directories(dir.path);
  const auto sweep = dir.path / "sweep.yaml";
  std::ofstream(sweep) << "base: nowhere.yaml\naxes:\n  grid.cell_size: 0.5\n";
  auto r = run_loam("compare " + sweep.string() + " --out " + (dir.path / "out").string());
  CHECK(r.exit_code == 2);
  CHECK(r.output.find(sweep.string() + ":3:19: error: axes.grid.cell_size: expected a non-empty "
                                       "list of values") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
}

TEST_CASE("loam compare stops cleanly on SIGINT and the same command resumes the sweep",
          "[compare][interrupt]") {
  // Ctrl-C reaches the whole process group: the running variant stops with status
  // interrupted (exit 130) and the sweep after it, writing compare.csv, exit 130. Run again,
  // the interrupted variant is not "already done": it runs again, and the sweep completes.
  TempDir dir("compare_interrupt");
  std::filesystem::create_directories(dir.path);
  const auto sweep = dir.path / "sweep.yaml";
  std::ofstream(sweep) << "base: " << LOAM_SOURCE_DIR << "/configs/vibrating_bar.yaml\n"
                       << "set: [time.end=3000, output.every_time=1000]\n"
                       << "axes:\n  scheme.flip: [1.0, 0.99]\nthreads: 1\n";
  const auto out = dir.path / "out";
  const int code = loam_test::run_bash("set -m; " + std::string(LOAM_EXE) + " compare " +
                                       sweep.string() + " --out " + out.string() +
                                       " >/dev/null 2>&1 & pid=$!; sleep 1; kill -INT -$pid; "
                                       "wait $pid");
  int interrupted = 0, done = 0;
  for (const auto& e : std::filesystem::directory_iterator(out / "variants")) {
    if (!std::filesystem::exists(e.path() / "summary.json")) continue;
    auto s = nlohmann::json::parse(loam_test::slurp(e.path() / "summary.json"));
    (s["status"] == "interrupted" ? interrupted : done) += 1;
  }
  std::printf("compare after SIGINT: exit %d, %d variant(s) interrupted, %d done\n", code,
              interrupted, done);
  CHECK(code == 130);
  CHECK(interrupted == 1);
  CHECK(done == 0);
  CHECK(std::filesystem::exists(out / "compare.csv"));
  auto again = run_loam("compare " + sweep.string() + " --out " + out.string());
  INFO(again.output);
  CHECK(again.exit_code == 0);
  CHECK(again.output.find("already done") == std::string::npos);
  auto rows = read_csv(out / "compare.csv");
  REQUIRE(rows.size() == 3);
  const auto& h = rows[0];
  const size_t status = size_t(std::find(h.begin(), h.end(), "status") - h.begin());
  CHECK(rows[1][status] == "ok");
  CHECK(rows[2][status] == "ok");
}

TEST_CASE("loam compare: the sweep's own metrics, failed variants marked, honest plot messages",
          "[compare]") {
  TempDir dir("compare_metrics");
  std::filesystem::create_directories(dir.path);
  const auto sweep = dir.path / "sweep.yaml";
  // The vibrating bar's kinetic energy starts at its largest, the initial energy 1/2 m v0^2
  // (docs/verification.md, vibrating bar): 0.0625 J is the reference of `peak_kinetic`.
  std::ofstream(sweep) << "base: " << LOAM_SOURCE_DIR << "/configs/vibrating_bar.yaml\n"
                       << "set: [time.end=5]\n"
                       << "axes:\n  time.dt: [0.01, 1.0]\n"  // 1.0 s is far above the CFL limit
                       << "metrics:\n"
                       << "  - {name: peak_kinetic, column: kinetic_energy, of: max, "
                          "reference: 0.0625}\n"
                       << "  - {name: final_reaction, column: no_such_column, of: final}\n"
                       << "metric: peak_kinetic_error\nthreads: 1\n";
  const auto out = dir.path / "out";
  auto r = run_loam("compare " + sweep.string() + " --out " + out.string());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  auto rows = read_csv(out / "compare.csv");
  REQUIRE(rows.size() == 3);
  const auto& h = rows[0];
  auto col = [&](const std::string& name) {
    return size_t(std::find(h.begin(), h.end(), name) - h.begin());
  };
  REQUIRE(col("peak_kinetic_error") < h.size());
  const auto& ok = rows[1];
  CHECK(ok[col("status")] == "ok");
  const double peak = std::stod(ok[col("peak_kinetic")]);
  std::printf("peak kinetic energy %.6g J (reference 0.0625 J), relative error %.3g\n", peak,
              std::stod(ok[col("peak_kinetic_error")]));
  CHECK(std::fabs(peak / 0.0625 - 1) < 0.02);
  CHECK(std::stod(ok[col("peak_kinetic_error")]) == Approx(peak / 0.0625 - 1).margin(1e-12));
  CHECK_THAT(ok[col("message")],
             Catch::Matchers::Contains("metric final_reaction: no column no_such_column"));
  CHECK(rows[2][col("status")] == "unstable");
  // The unstable variant is named as not plotted, its message whole (not cut).
  CHECK_THAT(r.output, Catch::Matchers::Contains("not plotted, marked in red: "
                                                 "time.dt=1.0 (unstable)"));
  CHECK_THAT(r.output, Catch::Matchers::Contains("unstable run at step"));
  CHECK(std::filesystem::exists(out / "pareto.png"));

  // A metric that no variant has: located, and the columns there are.
  std::string text = loam_test::slurp(sweep);
  text.replace(text.find("metric: peak_kinetic_error"), 26, "metric: peak_kinetik");
  std::ofstream(sweep) << text;
  auto bad = run_loam("compare " + sweep.string() + " --out " + out.string());
  CHECK(bad.exit_code == 0);
  CHECK_THAT(bad.output, Catch::Matchers::Contains(
                             "pareto.png not written: " + sweep.string() +
                             ":8:9: metric: 'peak_kinetik' is not a metric of any variant ("));
  CHECK_THAT(bad.output, Catch::Matchers::Contains("peak_kinetic_error"));
  CHECK(bad.output.find("--metric") == std::string::npos);
  CHECK(bad.output.find("matplotlib") == std::string::npos);
}

TEST_CASE("loam compare without any error metric says how to name one", "[compare]") {
  TempDir dir("compare_no_metric");
  std::filesystem::create_directories(dir.path);
  const auto sweep = dir.path / "sweep.yaml";
  std::ofstream(sweep) << "base: " << LOAM_SOURCE_DIR << "/configs/quickstart.yaml\n"
                       << "set: [time.end=0.01]\naxes:\n  shape_function: [linear]\nthreads: 1\n";
  auto r = run_loam("compare " + sweep.string() + " --out " + (dir.path / "out").string());
  INFO(r.output);
  CHECK(r.exit_code == 0);
  CHECK_THAT(r.output, Catch::Matchers::Contains(
                           "pareto.png not written: no metric named *error* (the variants have "
                           "none): name the column to plot with `metric:` in " +
                           sweep.string() + ", or define one under `metrics:` with a `reference`"));
  CHECK(r.output.find("--metric") == std::string::npos);
}

TEST_CASE("loam compare: a bad metrics entry is located, every error at once", "[compare]") {
  TempDir dir("compare_bad_metrics");
  std::filesystem::create_directories(dir.path);
  const auto sweep = dir.path / "sweep.yaml";
  std::ofstream(sweep) << "base: " << LOAM_SOURCE_DIR << "/configs/vibrating_bar.yaml\n"
                       << "axes:\n  grid.cell_size: [1.0]\n"
                       << "metrics:\n"
                       << "  - {name: a, colum: kinetic_energy}\n"
                       << "  - {name: b, column: kinetic_energy, of: peak}\n"
                       << "  - {name: c, column: kinetic_energy, reference: 0}\n";
  auto r = run_loam("compare " + sweep.string() + " --out " + (dir.path / "out").string());
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK_THAT(r.output, Catch::Matchers::Contains(sweep.string() +
                                                 ":5:15: error: metrics.0.colum: unknown key "
                                                 "'colum'; did you mean 'column'?"));
  CHECK_THAT(r.output, Catch::Matchers::Contains(sweep.string() + ":6:43: error: metrics.1.of: "
                                                                  "unknown value 'peak'"));
  CHECK_THAT(r.output, Catch::Matchers::Contains(
                           sweep.string() +
                           ":7:50: error: metrics.2.reference: a reference of 0 has no relative "
                           "error; give the value it should have"));
  CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
}
