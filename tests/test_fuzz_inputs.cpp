// A fuzzed input suite: configs mutated from the shipped ones (typos,
// deleted and duplicated lines, wrong types, junk characters, extreme numbers, empty maps, a cut
// file) go through `loam check` (1200 of them) and a sample through a short `loam run` (60):
// never a crash, a hang (20 s limit) or an exit code other than 0 or 2 (check) / 0, 2 or 3 (run),
// and every line of an exit-2 report is FILE:LINE:COL: error: ... Deterministic: one seed.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::stringstream ss(text);
  for (std::string l; std::getline(ss, l);) lines.push_back(l);
  return lines;
}

std::string join_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const auto& l : lines) out += l + "\n";
  return out;
}

/// One random mutation of a config's text (what it did goes to `what`).
std::string mutate(const std::string& text, std::mt19937& rng, std::string& what) {
  auto lines = split_lines(text);
  auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n - 1)(rng); };
  // Lines that carry YAML (not comments or blank).
  std::vector<size_t> yaml;
  for (size_t i = 0; i < lines.size(); ++i)
    if (!lines[i].empty() && lines[i].find_first_not_of(' ') != std::string::npos &&
        lines[i][lines[i].find_first_not_of(' ')] != '#')
      yaml.push_back(i);
  if (yaml.empty()) return text;
  const size_t li = yaml[pick(yaml.size())];
  std::string& l = lines[li];
  static const std::vector<std::string> numbers = {"1e308",
                                                   "-1e308",
                                                   "nan",
                                                   ".nan",
                                                   ".inf",
                                                   "-.inf",
                                                   "0",
                                                   "-1",
                                                   "1e-308",
                                                   "abc",
                                                   "[]",
                                                   "{}",
                                                   "[1, 2, 3, 4]",
                                                   "\"\"",
                                                   "true",
                                                   "~",
                                                   "99999999999999999999"};
  static const std::vector<std::string> junk = {"@", "#", "\t", ":", "{", "}", "[", "]",  ",",
                                                "&", "*", "!",  "%", "|", ">", "'", "\"", "\\"};
  switch (pick(8)) {
    case 0:  // delete a line
      what = "delete line " + std::to_string(li + 1);
      lines.erase(lines.begin() + long(li));
      break;
    case 1:  // duplicate a line
      what = "duplicate line " + std::to_string(li + 1);
      lines.insert(lines.begin() + long(li), l);
      break;
    case 2: {  // a typo in a key: swap two letters before the first ':'
      const size_t colon = l.find(':');
      const size_t start = l.find_first_not_of(" -{");
      if (colon != std::string::npos && start != std::string::npos && colon > start + 1) {
        const size_t a = start + pick(colon - start - 1);
        std::swap(l[a], l[a + 1]);
      }
      what = "typo at line " + std::to_string(li + 1);
      break;
    }
    case 3:
    case 4: {  // replace a number with an extreme or wrong-typed value
      static const std::regex number(R"(-?[0-9]+(\.[0-9]*)?([eE][-+]?[0-9]+)?)");
      std::vector<std::smatch> found;
      for (auto it = std::sregex_iterator(l.begin(), l.end(), number); it != std::sregex_iterator();
           ++it)
        found.push_back(*it);
      const std::string value = numbers[pick(numbers.size())];
      if (!found.empty()) {
        const auto& m = found[pick(found.size())];
        l.replace(size_t(m.position()), size_t(m.length()), value);
      } else {
        l += " " + value;
      }
      what = "value " + value + " at line " + std::to_string(li + 1);
      break;
    }
    case 5: {  // junk characters
      const std::string j = junk[pick(junk.size())];
      l.insert(pick(l.size() + 1), j);
      what = "junk '" + j + "' at line " + std::to_string(li + 1);
      break;
    }
    case 6: {  // a value replaced by an empty map
      const size_t colon = l.find(": ");
      if (colon != std::string::npos) l = l.substr(0, colon) + ": {}";
      what = "empty map at line " + std::to_string(li + 1);
      break;
    }
    default: {  // the file cut short
      const std::string all = join_lines(lines);
      const size_t at = pick(all.size());
      what = "cut at byte " + std::to_string(at);
      return all.substr(0, at);
    }
  }
  return join_lines(lines);
}

struct Outcome {
  int code = -1;
  std::string err;
};

/// `loam ARGS` with a 20 s limit (exit 124 on a hang); stderr captured, stdout discarded.
Outcome run_limited(const std::string& args) {
  const std::string cmd = "timeout 20 " + std::string(LOAM_EXE) + " " + args + " 2>&1 >/dev/null";
  Outcome o;
  FILE* pipe = popen(cmd.c_str(), "r");
  REQUIRE(pipe);
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) o.err.append(buf, n);
  const int status = pclose(pipe);
  o.code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  return o;
}

/// Every line of an exit-2 report is located: FILE:LINE:COL: error: ...
bool all_located(const std::string& err) {
  static const std::regex located(R"(^.+:[0-9]+:[0-9]+: error: .*$)");
  if (err.empty()) return false;
  for (const auto& l : split_lines(err))
    if (!std::regex_match(l, located)) return false;
  return true;
}

/// `checks` mutated copies of the shipped configs through `loam check`, then `runs` through a
/// short `loam run`: every exit is 0, 2 with located errors only, or (a run) 3; never a crash or
/// a hang. `seed` picks the mutations.
void fuzz_configs(int checks, int runs, unsigned seed) {
  std::vector<fs::path> sources;
  for (const auto& e : fs::directory_iterator(fs::path(LOAM_SOURCE_DIR) / "configs"))
    if (e.path().extension() == ".yaml") sources.push_back(e.path());
  std::sort(sources.begin(), sources.end());
  REQUIRE(sources.size() >= 20);
  loam_test::TempDir dir("fuzz");
  fs::create_directories(dir.path);
  std::mt19937 rng(seed);
  int accepted = 0, rejected = 0, bad = 0;
  for (int k = 0; k < checks + runs; ++k) {
    const fs::path& src = sources[size_t(k) % sources.size()];
    std::string what;
    std::string text = mutate(loam_test::slurp(src), rng, what);
    if (k % 3 == 0) text = mutate(text, rng, what += ", then ");  // some get two mutations
    const fs::path cfg = dir.path / ("m" + std::to_string(k) + ".yaml");
    std::ofstream(cfg) << text;
    const bool run = k >= checks;
    const fs::path out = dir.path / ("out" + std::to_string(k));
    const Outcome o =
        run_limited(run ? "run " + cfg.string() + " --quiet --threads 1 --out " + out.string() +
                              " --set time.end=1e-4 --set output.every_time=1e-4"
                        : "check " + cfg.string());
    const bool ok_code = o.code == 0 || o.code == 2 || (run && o.code == 3);
    const bool ok = ok_code && (o.code != 2 || all_located(o.err));
    if (o.code == 0) ++accepted;
    if (o.code == 2) ++rejected;
    if (!ok) {
      ++bad;
      std::printf("FUZZ %s of %s (%s): exit %d\n%s\n", run ? "run" : "check",
                  src.filename().c_str(), what.c_str(), o.code, o.err.c_str());
    }
    CHECK(ok);
    if (ok) fs::remove(cfg);
    fs::remove_all(out);
  }
  std::printf("fuzzed configs: %d checks and %d runs, %d accepted, %d rejected (located), %d bad\n",
              checks, runs, accepted, rejected, bad);
}

}  // namespace

TEST_CASE("fuzzed configs: never a crash, a hang or an unlocated error", "[fuzz][bad_config]") {
  fuzz_configs(300, 30, 20261202);
}

TEST_CASE("fuzzed configs, eight times as many: never a crash, a hang or an unlocated error",
          "[fuzz][bad_config][full]") {
  fuzz_configs(2400, 120, 20261205);
}
