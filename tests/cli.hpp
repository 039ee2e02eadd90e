#pragma once
// Helpers for tests that run the real `loam` command line (regression scenes).
#include <hdf5.h>

#include <catch2/catch.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace loam_test {

struct CliResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

/// Run a shell command; its exit code and its stdout and stderr together.
inline CliResult run_command(const std::string& command) {
  CliResult r;
  const std::string cmd = command + " 2>&1";
  FILE* pipe = popen(cmd.c_str(), "r");
  char buf[4096];
  while (size_t n = fread(buf, 1, sizeof buf, pipe)) r.output.append(buf, n);
  int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

inline CliResult run_loam(const std::string& args) {
  return run_command(std::string(LOAM_EXE) + " " + args);
}

/// Columns of a CSV file written by loam (probe_*.csv, history.csv) by header name; empty if the
/// file does not exist.
inline std::map<std::string, std::vector<double>> read_csv_columns(
    const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  std::getline(in, line);
  std::vector<std::string> names;
  std::stringstream hs(line);
  for (std::string c; std::getline(hs, c, ',');) names.push_back(c);
  std::map<std::string, std::vector<double>> cols;
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string c;
    for (size_t k = 0; k < names.size() && std::getline(ls, c, ','); ++k)
      cols[names[k]].push_back(std::stod(c));
  }
  return cols;
}

/// A dataset of an HDF5 particle frame (all components, row-major) read as `type`; empty if the
/// frame has no such dataset (a field the frame's set does not store).
template <class T>
std::vector<T> read_frame_dataset(const std::filesystem::path& file, const std::string& name,
                                  hid_t type) {
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  std::vector<T> v;
  if (H5Lexists(f, name.c_str(), H5P_DEFAULT) > 0) {
    hid_t ds = H5Dopen2(f, name.c_str(), H5P_DEFAULT);
    hid_t space = H5Dget_space(ds);
    v.resize(size_t(H5Sget_simple_extent_npoints(space)));
    if (!v.empty()) H5Dread(ds, type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data());
    H5Sclose(space);
    H5Dclose(ds);
  }
  H5Fclose(f);
  return v;
}
inline std::vector<double> read_frame_doubles(const std::filesystem::path& file,
                                              const std::string& name) {
  return read_frame_dataset<double>(file, name, H5T_NATIVE_DOUBLE);
}
inline std::vector<int> read_frame_ids(const std::filesystem::path& file) {
  return read_frame_dataset<int>(file, "id", H5T_NATIVE_INT);
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

/// Write `yaml` to dir/run.yaml and run it (quiet) into dir/out.
inline CliResult run_yaml(const std::filesystem::path& dir, const std::string& yaml,
                          const std::string& args = "") {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "run.yaml") << yaml;
  return run_loam("run " + (dir / "run.yaml").string() + " --quiet --out " +
                  (dir / "out").string() + " " + args);
}

/// `yaml` run as dir/run.yaml must be refused: exit code 2, an error at `location` (e.g.
/// "run.yaml:2:") carrying `message`, and no output directory.
inline void check_located_error(const std::filesystem::path& dir, const std::string& yaml,
                                const std::string& location, const std::string& message) {
  std::filesystem::remove_all(dir / "out");
  const CliResult r = run_yaml(dir, yaml);
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find(location) != std::string::npos);
  CHECK(r.output.find(message) != std::string::npos);
  CHECK(!std::filesystem::exists(dir / "out"));
}

/// Run a bash script through a real shell (for what a function call cannot show: signals to a
/// running process, ulimit) and return the exit code of its last command, `$?`, which it
/// writes to a file (std::system reports the shell's own status). No single quote in it.
inline int run_bash(const std::string& script) {
  static int count = 0;
  const auto rc = std::filesystem::temp_directory_path() /
                  ("loam_test_rc_" + std::to_string(getpid()) + "_" + std::to_string(count++));
  const std::string cmd = "bash -c '" + script + "; echo $? > " + rc.string() + "'";
  REQUIRE(std::system(cmd.c_str()) == 0);
  int code = -1;
  std::ifstream(rc) >> code;
  std::filesystem::remove(rc);
  return code;
}

/// Whether a directory holds a file with the .tmp extension (an output not completed).
inline bool has_tmp_files(const std::filesystem::path& dir) {
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (e.path().extension() == ".tmp") return true;
  return false;
}

/// The whole text of a file.
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// Run a config from configs/ (with extra arguments) into `out` and return its summary.json.
inline nlohmann::json run_scene(const std::string& config, const std::filesystem::path& out,
                                const std::string& extra = "") {
  CliResult r = run_loam(std::string("run ") + LOAM_SOURCE_DIR + "/configs/" + config +
                         " --quiet --out " + out.string() + " " + extra);
  if (r.exit_code != 0) throw std::runtime_error("loam run " + config + " failed:\n" + r.output);
  std::ifstream in(out / "summary.json");
  return nlohmann::json::parse(in);
}

/// A bad material parameter set and the one error line `loam run` must print for it.
struct BadMaterial {
  std::string params;  // appended to the material map
  std::string line;    // the output after the config path: ":7:COL: error: key.path: message"
};

/// For each case, write run.yaml with one 1D body `body` whose line 7 is
/// `    material: {<material><params>}`, run `loam run` on it and check exit code 2, that the
/// output is exactly the one line <config path><line>, and that no output directory was made.
inline void check_bad_material(const std::string& material, const std::vector<BadMaterial>& cases,
                               const std::string& body = "bar") {
  TempDir dir("bad_material");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "run.yaml";
  for (const auto& k : cases) {
    std::ofstream(cfg) << "grid:\n  extent: [4]\n  cell_size: 1\nbodies:\n  - name: " << body
                       << "\n    generator: {type: box, min: [0], max: [2]}\n"
                          "    material: {"
                       << material << k.params << "}\ntime:\n  end: 0.1\n";
    auto r = run_loam("run " + cfg.string() + " --quiet --out " + (dir.path / "out").string());
    std::printf("%s", r.output.c_str());
    CHECK(r.exit_code == 2);
    CHECK(r.output == cfg.string() + k.line + "\n");  // exactly this one line (column: value)
    CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
  }
}

}  // namespace loam_test
