// The core names no concrete plugin: framework/ (framework/mpi/ included) includes nothing from
// the plugin directories, nor from the executable's commands (app/) or the benchmarks (bench/),
// and no framework source spells a registered plugin's name as a string literal
// (docs/architecture.md).
#include <catch2/catch.hpp>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "cli.hpp"
#include "framework/registry.hpp"

namespace fs = std::filesystem;

TEST_CASE("framework/ includes nothing from plugins, app/ or bench/ and names no plugin",
          "[layout]") {
  std::vector<std::string> names;
  for (const auto& k : loam::Registry::instance().kinds())
    for (const auto& n : loam::Registry::instance().names(k.name)) names.push_back(n);
  REQUIRE(names.size() >= 15);
  int files = 0;
  for (const auto& e : fs::recursive_directory_iterator(fs::path(LOAM_SOURCE_DIR) / "framework")) {
    std::string ext = e.path().extension().string();
    if (ext != ".cpp" && ext != ".hpp" && ext != ".in") continue;
    ++files;
    std::ifstream in(e.path());
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    INFO(e.path().filename().string());
    for (const char* dir : {"materials/", "shapefunctions/", "schemes/", "plugins/", "app/",
                            "bench/", "../app/", "../bench/"})
      CHECK(text.find(std::string("#include \"") + dir) == std::string::npos);
    for (const auto& n : names) {
      INFO("plugin name " << n);
      CHECK(text.find("\"" + n + "\"") == std::string::npos);
    }
  }
  CHECK(files > 10);
}

TEST_CASE("docs/plugins.md and docs/config.md are generated from the current schemas", "[layout]") {
  // Regenerate with: build/loam plugins --markdown > docs/plugins.md;
  //                  build/loam schema --markdown > docs/config.md
  for (auto [cmd, file] : {std::pair<std::string, std::string>{"plugins --markdown", "plugins.md"},
                           std::pair<std::string, std::string>{"schema --markdown", "config.md"}}) {
    std::string out;
    FILE* pipe = popen((std::string(LOAM_EXE) + " " + cmd).c_str(), "r");
    char buf[4096];
    while (size_t n = fread(buf, 1, sizeof buf, pipe)) out.append(buf, n);
    pclose(pipe);
    std::ifstream in(fs::path(LOAM_SOURCE_DIR) / "docs" / file);
    std::stringstream ss;
    ss << in.rdbuf();
    INFO("docs/" << file << " is stale: regenerate it with `loam " << cmd << "`");
    CHECK(ss.str() == out);
  }
}

TEST_CASE("test names contain no semicolon (ctest would split them and run nothing)", "[layout]") {
  int cases = 0;
  for (const auto& e : fs::directory_iterator(fs::path(LOAM_SOURCE_DIR) / "tests")) {
    if (e.path().extension() != ".cpp") continue;
    std::ifstream in(e.path());
    std::stringstream ss;
    ss << in.rdbuf();
    const std::string text = ss.str();
    for (size_t pos = 0; (pos = text.find("TEST_CASE(\"", pos)) != std::string::npos; ++pos) {
      const size_t end = text.find('"', pos + 11);
      const std::string name = text.substr(pos + 11, end - pos - 11);
      INFO(e.path().filename().string() << ": " << name);
      CHECK(name.find(';') == std::string::npos);
      ++cases;
    }
  }
  CHECK(cases > 20);
}

TEST_CASE("every built-in plugin is one file named as its YAML type, in its kind's folder",
          "[layout]") {
  // One concept per file, grouped by kind (docs/architecture.md, Layout): materials/,
  // shapefunctions/, schemes/, plugins/<kind>/. A plugin registered by the test binary itself or
  // loaded from a library is not built-in and is skipped.
  const std::map<std::string, std::string> folder = {
      {"material", "materials"},     {"shape_function", "shapefunctions"},
      {"scheme", "schemes"},         {"boundary", "plugins/boundaries"},
      {"load", "plugins/loads"},     {"damping", "plugins/damping"},
      {"drag", "plugins/drag"},      {"generator", "plugins/generators"},
      {"field", "plugins/fields"},   {"reference", "plugins/references"},
      {"writer", "plugins/writers"}, {"source", "plugins/sources"},
      {"sink", "plugins/sinks"},     {"time_function", "plugins/time_functions"},
      {"contact", "plugins/contact"}};
  auto& reg = loam::Registry::instance();
  int checked = 0;
  for (const auto& k : reg.kinds()) {
    INFO("kind " << k.name);
    REQUIRE(folder.count(k.name) == 1);
    for (const auto& n : reg.names(k.name)) {
      if (reg.find(k.name, n)->origin != "built-in") continue;
      const fs::path file = fs::path(LOAM_SOURCE_DIR) / folder.at(k.name) / (n + ".cpp");
      INFO(file.string());
      CHECK(fs::exists(file));
      ++checked;
    }
  }
  CHECK(checked >= 30);
}

TEST_CASE("every seedNNN config names the paper it reproduces in its first line", "[layout]") {
  // docs/verification.md lists the papers; a config's header starts "# Paper (seed NNN):".
  int checked = 0;
  for (const auto& e : fs::directory_iterator(fs::path(LOAM_SOURCE_DIR) / "configs")) {
    const std::string n = e.path().filename().string();
    if (n.rfind("seed", 0) != 0 || e.path().extension() != ".yaml") continue;
    std::ifstream in(e.path());
    std::string first;
    std::getline(in, first);
    INFO(n << ": " << first);
    CHECK(first.rfind("# Paper (seed " + n.substr(4, 3) + "):", 0) == 0);
    ++checked;
  }
  std::printf("seed configs with their paper named: %d\n", checked);
  CHECK(checked >= 7);
}

TEST_CASE("every run file in configs/ passes loam check", "[layout]") {
  // A shipped scene must stay valid when keys or plugins change (renamed keys give exit 2).
  int checked = 0;
  for (const auto& e : fs::directory_iterator(fs::path(LOAM_SOURCE_DIR) / "configs")) {
    if (e.path().extension() != ".yaml") continue;
    const auto r = loam_test::run_loam("check " + e.path().string());
    INFO(e.path().filename().string() << ": " << r.output);
    CHECK(r.exit_code == 0);
    ++checked;
  }
  std::printf("run files in configs/ that pass loam check: %d\n", checked);
  CHECK(checked >= 15);
}
