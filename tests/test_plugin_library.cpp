// Out-of-tree plugins (docs/architecture.md "Plugins"): the example library built from
// plugins/examples/ is loaded by a run file's `plugins:` list and runs through the real command
// line; a missing library and a library without the ABI symbol are input errors (exit 2).
#include <sys/wait.h>
#include <unistd.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "cli.hpp"
#include "framework/registry.hpp"

namespace {

namespace fs = std::filesystem;
using loam_test::run_loam;
using loam_test::TempDir;

/// A 1D bar of the example Kelvin-Voigt material vibrating in its first mode, in the style of
/// configs/vibrating_bar.yaml: L = 25 m, E = 100 Pa, rho = 1 kg/m^3, c = 10 m/s, period 10 s.
/// `plugin` is written as given (a relative path is relative to the run file).
std::string bar_config(const std::string& plugin, double end_time) {
  std::ostringstream s;
  s << "plugins: [" << plugin << "]\n"
    << "grid:\n"
    << "  origin: [0]\n"
    << "  extent: [27]\n"
    << "  cell_size: 1.0\n"
    << "bodies:\n"
    << "  - name: bar\n"
    << "    generator: {type: box, min: [0], max: [25]}\n"
    << "    particles_per_cell: 2\n"
    << "    material: {type: example_kelvin_voigt, E: 100, nu: 0, density: 1, viscosity: 10}\n"
    << "    velocity: {type: sine, amplitude: [0.1], wavenumber: [0.06283185307179587]}\n"
    << "boundaries:\n"
    << "  - {type: fixed, face: x-}\n"
    << "time: {end: " << end_time << ", cfl: 0.1}\n"
    << "output:\n"
    << "  every_time: 5.0\n"
    << "  fields: [velocity, stress, viscous_stress]\n";
  return s.str();
}

nlohmann::json read_json(const fs::path& p) {
  std::ifstream in(p);
  return nlohmann::json::parse(in);
}

double mechanical_energy(const nlohmann::json& e) {
  return e["kinetic"].get<double>() + e["strain"].get<double>();
}

}  // namespace

TEST_CASE("a run file loads the example plugin library and runs its material", "[plugins]") {
  TempDir dir("plugin_library");
  fs::create_directories(dir.path);
  const fs::path lib = LOAM_EXAMPLE_PLUGIN;
  REQUIRE(fs::exists(lib));
  // Relative to the run file, as a researcher would write it next to their library.
  const std::string rel = fs::relative(lib, dir.path).string();
  const fs::path config = dir.path / "bar.yaml";
  std::ofstream(config) << bar_config(rel, 10.0);

  auto check = run_loam("check " + config.string());
  INFO(check.output);
  CHECK(check.exit_code == 0);

  // The first mode (w = pi c / 2L) of a Kelvin-Voigt bar has damping ratio z = eta w / (2 E), so
  // its energy decays as exp(-2 z w t); over one period, with eta = 10 Pa s: 0.674.
  // 50 particles: one thread (two threads spin-wait badly when the machine is busy).
  auto r = run_loam("run " + config.string() + " --threads 1 --quiet --out " +
                    (dir.path / "out").string());
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  REQUIRE(fs::exists(dir.path / "out" / "summary.json"));
  auto s = read_json(dir.path / "out" / "summary.json");
  CHECK(s["status"] == "ok");
  CHECK(s["config"]["plugins"][0] == rel);
  CHECK(s["config"]["bodies"][0]["material"]["type"] == "example_kelvin_voigt");
  CHECK(s["config"]["bodies"][0]["material"]["viscosity"] == 10.0);
  const double pi = std::acos(-1.0), w = pi * 10.0 / (2 * 25.0), z = 10.0 * w / (2 * 100.0);
  const double expected = std::exp(-2 * z * w * s["end_time"].get<double>());
  const double ratio =
      mechanical_energy(s["energy_final"]) / mechanical_energy(s["energy_initial"]);
  INFO("energy ratio " << ratio << ", Kelvin-Voigt first mode " << expected);
  CHECK(std::abs(ratio - expected) < 0.01);

  // Without the dashpot the same library is the elastic bar: energy is kept.
  auto e = run_loam("run " + config.string() + " --threads 1 --quiet --out " +
                    (dir.path / "elastic").string() + " --set bodies.0.material.viscosity=0");
  INFO(e.output);
  REQUIRE(e.exit_code == 0);
  auto se = read_json(dir.path / "elastic" / "summary.json");
  const double kept =
      mechanical_energy(se["energy_final"]) / mechanical_energy(se["energy_initial"]);
  INFO("energy ratio without viscosity " << kept);
  CHECK(std::abs(kept - 1.0) < 0.01);
}

TEST_CASE("a missing plugin library is an input error at its place in the run file", "[plugins]") {
  TempDir dir("plugin_missing");
  fs::create_directories(dir.path);
  const fs::path config = dir.path / "bar.yaml";
  std::ofstream(config) << bar_config("lib/libnot_there.so", 1.0);
  auto r = run_loam("run " + config.string() + " --quiet --out " + (dir.path / "out").string());
  INFO(r.output);
  CHECK(r.exit_code == 2);
  // Line 1, column 11: the list entry after "plugins: [".
  const std::string expected = config.string() +
                               ":1:11: error: plugins.0: plugin library not found: " +
                               (dir.path / "lib/libnot_there.so").string();
  CHECK(r.output.find(expected + "\n") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "out"));
}

TEST_CASE("a shared library without loam_plugin_abi_version is refused", "[plugins]") {
  TempDir dir("plugin_no_abi");
  fs::create_directories(dir.path);
  const fs::path config = dir.path / "bar.yaml";
  std::ofstream(config) << bar_config(LOAM_NOT_A_PLUGIN, 1.0);
  auto r = run_loam("run " + config.string() + " --quiet --out " + (dir.path / "out").string());
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find(config.string() + ":1:11: error: plugins.0: not a loam plugin library (no "
                                        "loam_plugin_abi_version symbol)\n") != std::string::npos);
  CHECK_FALSE(fs::exists(dir.path / "out"));
}

TEST_CASE("the example library registers a documented material under its own origin", "[plugins]") {
  // Loads into this test process; the registry then lists the example like a built-in.
  REQUIRE(loam::load_plugin_library(LOAM_EXAMPLE_PLUGIN) == "");
  const auto* info = loam::Registry::instance().find("material", "example_kelvin_voigt");
  REQUIRE(info != nullptr);
  CHECK(info->origin == LOAM_EXAMPLE_PLUGIN);
  CHECK_FALSE(info->summary.empty());
  std::vector<std::string> keys;
  for (const auto& p : info->schema().params) {
    INFO(p.key);
    CHECK_FALSE(p.doc.empty());
    CHECK_FALSE(p.unit.empty());
    keys.push_back(p.key);
  }
  CHECK(keys == std::vector<std::string>{"E", "nu", "density", "viscosity"});
}
