#pragma once
// Helpers for tests that run the real `loam` command line (regression scenes).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace loam_test {

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

inline CliResult run_loam(const std::string& args) {
  CliResult r;
  std::string cmd = std::string(LOAM_EXE) + " " + args + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) r.output.append(buf, n);
  int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

/// A fresh, empty directory under the system temp dir, removed when the object dies.
struct TempDir {
  std::filesystem::path path;
  explicit TempDir(const std::string& name) {
    path = std::filesystem::temp_directory_path() /
           ("loam_test_" + name + "_" + std::to_string(getpid()));
    std::filesystem::remove_all(path);
  }
  ~TempDir() { std::filesystem::remove_all(path); }
};

/// Run a config from configs/ (with extra arguments) into `out` and return its summary.json.
inline nlohmann::json run_scene(const std::string& config, const std::filesystem::path& out,
                                const std::string& extra = "") {
  CliResult r = run_loam(std::string("run ") + LOAM_SOURCE_DIR + "/configs/" + config +
                         " --quiet --out " + out.string() + " " + extra);
  if (r.exit_code != 0) throw std::runtime_error("loam run " + config + " failed:\n" + r.output);
  std::ifstream in(out / "summary.json");
  return nlohmann::json::parse(in);
}

}  // namespace loam_test
