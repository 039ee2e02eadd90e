// The README starts a newcomer: it is short, it opens with the two set-up commands (the second
// is the one .ci/run runs), and its links and those of the pages it sends readers to resolve.
// docs/scenes.md lists every shipped scene.
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace {

const fs::path kRoot = fs::path(LOAM_SOURCE_DIR);

std::string slurp_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> lines_of(const fs::path& file) {
  std::ifstream in(file);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  const size_t e = s.find_last_not_of(" \t\r");
  return s.substr(b, e - b + 1);
}

bool is_fence(const std::string& line) {
  return trim(line).rfind("```", 0) == 0;
}

/// The lines inside the first fenced code block of a markdown file.
std::vector<std::string> first_fenced_block(const std::vector<std::string>& lines) {
  std::vector<std::string> block;
  bool inside = false;
  for (const auto& line : lines) {
    if (is_fence(line)) {
      if (inside) return block;
      inside = true;
      continue;
    }
    if (inside) block.push_back(line);
  }
  return {};  // no closed block
}

/// The target of every markdown link and image outside fenced code blocks: `[text](target)`.
std::vector<std::string> link_targets(const std::vector<std::string>& lines) {
  static const std::regex link(R"(\]\(([^)\s]+)\))");
  std::vector<std::string> targets;
  bool inside = false;
  for (const auto& line : lines) {
    if (is_fence(line)) {
      inside = !inside;
      continue;
    }
    if (inside) continue;
    for (std::sregex_iterator it(line.begin(), line.end(), link), end; it != end; ++it)
      targets.push_back((*it)[1].str());
  }
  return targets;
}

bool is_relative(const std::string& target) {
  return target.rfind("http://", 0) != 0 && target.rfind("https://", 0) != 0 &&
         target.rfind("mailto:", 0) != 0 && target.rfind('#', 0) != 0;
}

/// The command .ci/run runs: its line that calls ctest, without the `|| status=$?` that keeps
/// its exit code.
std::string ci_command() {
  for (const auto& line : lines_of(kRoot / ".ci" / "run")) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#' || t.find("ctest") == std::string::npos) continue;
    const size_t keep = t.find(" || ");
    return trim(keep == std::string::npos ? t : t.substr(0, keep));
  }
  return "";
}

}  // namespace

TEST_CASE("README: short, opens with the two set-up commands, the second the one CI runs",
          "[docs][unit]") {
  const auto lines = lines_of(kRoot / "README.md");
  INFO("README.md has " << lines.size() << " lines");
  CHECK(lines.size() <= 130);
  CHECK(lines.size() >= 20);

  // The first fenced block comes before any prose: only the title and blank lines above it.
  size_t first_fence = 0;
  while (first_fence < lines.size() && !is_fence(lines[first_fence])) {
    const std::string t = trim(lines[first_fence]);
    INFO("line " << first_fence + 1 << ": " << t);
    CHECK((t.empty() || t.rfind("# ", 0) == 0));
    ++first_fence;
  }
  REQUIRE(first_fence < lines.size());

  std::vector<std::string> commands;
  for (const auto& line : first_fenced_block(lines))
    if (!trim(line).empty()) commands.push_back(trim(line));
  REQUIRE(commands.size() == 2);
  CHECK(commands[0].rfind("tools/setup.sh && build/loam run configs/", 0) == 0);
  CHECK(commands[1].rfind("tools/setup.sh --mpi && ", 0) == 0);

  const std::string ci = ci_command();
  INFO(".ci/run runs: " << ci);
  INFO("README's second command: " << commands[1]);
  REQUIRE(!ci.empty());
  CHECK(commands[1] == ci);

  // What the commands name exists: the set-up script and the scene the first one runs.
  static const std::regex path(R"((tools|configs)/[A-Za-z0-9_./-]+\.(sh|yaml))");
  int named = 0;
  for (const auto& c : commands)
    for (std::sregex_iterator it(c.begin(), c.end(), path), end; it != end; ++it) {
      INFO(it->str());
      CHECK(fs::exists(kRoot / it->str()));
      ++named;
    }
  CHECK(named >= 3);
}

TEST_CASE("README: the plot tools' packages and interpreter, as tools/setup.sh installs them",
          "[docs][unit]") {
  const std::string readme = slurp_text(kRoot / "README.md");
  const std::string setup = slurp_text(kRoot / "tools" / "setup.sh");
  for (const char* package : {"python3-h5py", "python3-matplotlib"}) {
    INFO(package);
    CHECK(readme.find(package) != std::string::npos);
    CHECK(setup.find(package) != std::string::npos);
  }
  CHECK(readme.find("/usr/bin/python3") != std::string::npos);
  CHECK(readme.find("particles.xdmf") != std::string::npos);
  CHECK(readme.find("summary.json") != std::string::npos);
  CHECK(readme.find("history.csv") != std::string::npos);
  CHECK(readme.find("h5py") != std::string::npos);
}

TEST_CASE("README and the docs it leads to: every relative link points at a file", "[docs][unit]") {
  int links = 0;
  for (const char* page : {"README.md", "docs/scenes.md", "docs/runs.md", "docs/modelling.md"}) {
    const fs::path file = kRoot / page;
    INFO(page);
    REQUIRE(fs::exists(file));
    for (std::string target : link_targets(lines_of(file))) {
      if (!is_relative(target)) continue;
      const size_t hash = target.find('#');
      if (hash != std::string::npos) target = target.substr(0, hash);
      INFO("link " << target);
      CHECK(fs::exists(file.parent_path() / target));
      ++links;
    }
  }
  CHECK(links >= 40);
}

TEST_CASE("docs/scenes.md names every run file shipped in configs/", "[docs][unit]") {
  const std::string scenes = slurp_text(kRoot / "docs" / "scenes.md");
  int checked = 0;
  for (const auto& e : fs::directory_iterator(kRoot / "configs")) {
    if (e.path().extension() != ".yaml") continue;
    const std::string name = e.path().filename().string();
    INFO(name);
    CHECK(scenes.find("`" + name + "`") != std::string::npos);
    ++checked;
  }
  CHECK(checked >= 20);
}
