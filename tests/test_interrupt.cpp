// A run stopped by SIGINT or SIGTERM (framework/interrupt.hpp) through a real process: the first
// signal lets the step finish and writes the last frame, the history, probes and summary.json
// (status: interrupted), exit 128 + signal; a second signal stops at once and leaves no .tmp
// file behind.
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "cli.hpp"

namespace {

/// Run the vibrating bar for a very long time in the background, send `signals` (e.g. "INT" or
/// "INT INT") after `delay` seconds and return the exit code.
int run_and_signal(const std::filesystem::path& out, const std::string& signals, double delay) {
  std::string kills;
  for (size_t a = 0, b; a < signals.size(); a = b + 1) {
    b = signals.find(' ', a);
    if (b == std::string::npos) b = signals.size();
    kills += "kill -" + signals.substr(a, b - a) + " $pid; ";
  }
  return loam_test::run_bash(std::string(LOAM_EXE) + " run " + LOAM_SOURCE_DIR +
                             "/configs/vibrating_bar.yaml --quiet --threads 1 --set time.end=1e5 "
                             "--out " +
                             out.string() + " 2>/dev/null & pid=$!; sleep " +
                             std::to_string(delay) + "; " + kills + "wait $pid");
}

}  // namespace

TEST_CASE("SIGINT and SIGTERM stop a run after its step with every file complete",
          "[interrupt][cli]") {
  for (const auto& [sig, expected] : {std::pair<std::string, int>{"INT", 130}, {"TERM", 143}}) {
    loam_test::TempDir dir("interrupt_" + sig);
    const int code = run_and_signal(dir.path, sig, 1.5);
    auto s = nlohmann::json::parse(loam_test::slurp(dir.path / "summary.json"));
    const long steps = s["steps"];
    // The frames the XDMF index lists are all there; the last one is the final step's.
    const std::string xdmf = loam_test::slurp(dir.path / "particles.xdmf");
    long frames = 0;
    for (size_t p = 0; (p = xdmf.find("<Time Value", p)) != std::string::npos; ++p) ++frames;
    char last[64];
    std::snprintf(last, sizeof last, "particles_%06ld.h5", frames - 1);
    const auto x = loam_test::read_frame_doubles(dir.path / last, "position");
    // The history's last row is the last step.
    std::ifstream hist(dir.path / "history.csv");
    std::string line, prev;
    while (std::getline(hist, line)) prev = line;
    const long last_row = std::stol(prev.substr(0, prev.find(',')));
    std::printf(
        "SIG%s: exit %d, status %s, %ld steps, t = %.3f s, %ld frames (last %s: %zu values), "
        "history ends at step %ld\n",
        sig.c_str(), code, s["status"].get<std::string>().c_str(), steps,
        s["end_time"].get<double>(), frames, last, x.size(), last_row);
    CHECK(code == expected);
    CHECK(s["status"] == "interrupted");
    CHECK(s["interrupted_by"] == "SIG" + sig);
    CHECK(steps > 0);
    CHECK(s["end_time"].get<double>() < 1e5);
    CHECK(frames >= 2);
    CHECK(!x.empty());
    char after[64];
    std::snprintf(after, sizeof after, "particles_%06ld.h5", frames);
    CHECK(!std::filesystem::exists(dir.path / after));  // no frame outside the index
    CHECK(last_row == steps);
    CHECK(!loam_test::has_tmp_files(dir.path));
  }
}

TEST_CASE("a second signal stops at once and leaves no temporary file", "[interrupt][cli]") {
  // The two signals arrive together: the run ends with 130 whether the second one caught it in
  // the middle of its last writes or after them; either way no .tmp file may remain.
  loam_test::TempDir dir("interrupt_twice");
  const int code = run_and_signal(dir.path, "INT INT", 1.0);
  std::printf("SIGINT twice: exit %d, summary %s\n", code,
              std::filesystem::exists(dir.path / "summary.json") ? "written" : "not written");
  CHECK(code == 130);
  CHECK(!loam_test::has_tmp_files(dir.path));
}
