// Particle sets (framework/particle_set.hpp): several sets of material points on one grid.
// single_phase sums all its sets onto one velocity field, so splitting a body over two sets must
// not change the physics: the particles' trajectories may differ only by the summation order
// of the scatter (round-off). Each set gets its own frames (<set>.xdmf, <set>_NNNNNN.h5), counts
// in summary.json, and stores only the fields its bodies need.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>

#include "cli.hpp"

namespace fs = std::filesystem;
using namespace loam_test;

namespace {

/// The granular collapse of configs/granular_collapse_2d.yaml (a = 2, cell 0.02 m) with its
/// column split at x = 0.1 m into bodies `left` and `right`, in one set or in sets of their own.
/// `right_material` replaces the right half's material when given.
std::string split_collapse(bool two_sets, const std::string& right_material = "") {
  const std::string mc =
      "{type: mohr_coulomb, E: 5.0e6, nu: 0.3, density: 1800, c: 0, phi: 30, psi: 0}";
  auto body = [&](const std::string& name, double x0, double x1, const std::string& mat) {
    std::ostringstream b;
    b << "  - name: " << name << "\n"
      << (two_sets ? "    set: " + name + "\n" : "") << "    generator: {type: box, min: [" << x0
      << ", 0], max: [" << x1 << ", 0.4]}\n"
      << "    particles_per_cell: 2\n"
      << "    material: " << mat << "\n"
      << "    stress: {type: linear_profile, axis: 1, value: [-3531.6, -7063.2, -3531.6, 0], "
         "gradient: [8829.0, 17658.0, 8829.0, 0]}\n";
    return b.str();
  };
  return std::string(
             "grid: {origin: [0, 0], extent: [1.2, 0.44], cell_size: 0.02}\n"
             "shape_function: linear\n"
             "scheme: {type: single_phase, update: musl, flip: 0.98") +
         (two_sets ? ", sets: [left, right]" : "") +
         "}\n"
         "gravity: [0, -9.81]\n"
         "bodies:\n" +
         body("left", 0, 0.1, mc) +
         body("right", 0.1, 0.2, right_material.empty() ? mc : right_material) +
         "boundaries:\n"
         "  - {type: slip, face: x-}\n"
         "  - {type: friction, face: y-, coefficient: 0.5}\n"
         "time: {end: 1.0, cfl: 0.5}\n"
         "output: {every_time: 0.5, fields: [velocity, stress, plastic_strain_eq]}\n";
}

/// Positions (x, y) by particle id over the frame files of one output time.
std::map<int, std::array<double, 2>> positions_by_id(const std::vector<fs::path>& frames) {
  std::map<int, std::array<double, 2>> m;
  for (const auto& f : frames) {
    const auto x = read_frame_doubles(f, "position");  // padded to 3 components
    const auto id = read_frame_ids(f);
    for (size_t i = 0; i < id.size(); ++i) m[id[i]] = {x[3 * i], x[3 * i + 1]};
  }
  return m;
}

struct Deposit {
  double runout = 0, height = 0;
};
/// Front (largest x + half spacing) and top (largest y + half spacing) of the deposit.
Deposit deposit(const std::map<int, std::array<double, 2>>& x) {
  Deposit d{-1e300, -1e300};
  for (const auto& [id, p] : x) {
    d.runout = std::max(d.runout, p[0] + 0.005);
    d.height = std::max(d.height, p[1] + 0.005);
  }
  d.runout -= 0.2;  // L_f - L0
  return d;
}

nlohmann::json summary(const TempDir& dir) {
  std::ifstream in(dir.path / "out" / "summary.json");
  return nlohmann::json::parse(in);
}

}  // namespace

TEST_CASE("granular collapse split over two sets: same run-out and height as one set",
          "[sets][scene]") {
  // Mechanism: single_phase sums every set onto one velocity field, so the two halves of the
  // column interact exactly as in one set; only the order of the nodal sums may change.
  // Tolerance: 1e-12 m on every particle position after 1 s (about 8800 steps of a collapsing,
  // frictional flow, where a real coupling difference would show at the mm scale).
  // Two threads cut the sets into several slabs (another summation order); on a loaded 2-core
  // machine small 2-thread runs crawl, so that case runs the first 0.25 s (the collapse phase).
  for (int threads : {1, 2}) {
    TempDir one("sets_one_" + std::to_string(threads)), two("sets_two_" + std::to_string(threads));
    const std::string args =
        "--threads " + std::to_string(threads) +
        (threads == 2 ? " --set time.end=0.25 --set output.every_time=0.125" : "");
    REQUIRE(run_yaml(one.path, split_collapse(false), args).exit_code == 0);
    REQUIRE(run_yaml(two.path, split_collapse(true), args).exit_code == 0);
    const auto a = positions_by_id({one.path / "out/particles_000002.h5"});
    const auto b =
        positions_by_id({two.path / "out/left_000002.h5", two.path / "out/right_000002.h5"});
    REQUIRE(a.size() == 800);
    REQUIRE(b.size() == a.size());
    double worst = 0;
    for (const auto& [id, p] : a) {
      REQUIRE(b.count(id) == 1);
      for (int d = 0; d < 2; ++d)
        worst = std::max(worst, std::fabs(p[size_t(d)] - b.at(id)[size_t(d)]));
    }
    const Deposit da = deposit(a), db = deposit(b);
    std::printf(
        "granular collapse, %d thread(s): one set run-out %.15f m height %.15f m; two sets "
        "%.15f m / %.15f m; largest position difference %.3g m (tolerance 1e-12 m)\n",
        threads, da.runout, da.height, db.runout, db.height, worst);
    CHECK(worst <= 1e-12);
    CHECK(std::fabs(da.runout - db.runout) <= 1e-12);
    CHECK(std::fabs(da.height - db.height) <= 1e-12);
    CHECK(da.runout > 0.1);  // the column did spread (Lube 2005: (L_f - L0) = 2.48 L0 at rest)
    // The summary counts every set; the history's total is the same.
    const auto s1 = summary(one), s2 = summary(two);
    CHECK(s2["particles"] == 800);
    CHECK(s2["sets"]["left"]["particles"] == 400);
    CHECK(s2["sets"]["right"]["particles"] == 400);
    CHECK(s2["sets"]["left"]["bodies"] == nlohmann::json::array({"left"}));
    CHECK(s1["sets"]["particles"]["particles"] == 800);
    const double k1 = s1["energy_final"]["kinetic"], k2 = s2["energy_final"]["kinetic"];
    CHECK(std::fabs(k1 - k2) <= 1e-12 * std::max(1.0, std::fabs(k1)));
  }
}

TEST_CASE("each set has its own ParaView frames and stores only its bodies' fields", "[sets]") {
  // Right half linear elastic: plastic_strain_eq (Mohr-Coulomb state) exists only in `left`.
  TempDir dir("sets_output");
  auto r = run_yaml(
      dir.path, split_collapse(true, "{type: linear_elastic, E: 5.0e6, nu: 0.3, density: 1800}"),
      "--threads 1 --set time.end=0.1 --set output.every_time=0.05");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const fs::path out = dir.path / "out";
  for (const std::string set : {"left", "right"}) {
    const std::string x = slurp(out / (set + ".xdmf"));
    // Three frames (t = 0, 0.05, 0.1), each naming its own existing file with 400 points.
    std::regex file_re(set + "_\\d{6}\\.h5");
    int frames = 0;
    for (auto it = std::sregex_iterator(x.begin(), x.end(), file_re); it != std::sregex_iterator();
         ++it)
      ++frames;
    const std::string last = out / (set + "_000002.h5");
    std::printf("%s.xdmf: %d dataset references, NumberOfElements=\"400\": %s\n", set.c_str(),
                frames, x.find("NumberOfElements=\"400\"") != std::string::npos ? "yes" : "no");
    CHECK(frames >= 3);
    CHECK(fs::exists(last));
    CHECK(read_frame_ids(last).size() == 400);
    CHECK(x.find("NumberOfElements=\"400\"") != std::string::npos);
    const bool has_eq = !read_frame_doubles(last, "plastic_strain_eq").empty();
    CHECK(has_eq == (set == "left"));
    CHECK((x.find("plastic_strain_eq") != std::string::npos) == (set == "left"));
  }
  const auto s = summary(dir);
  const size_t bl = s["sets"]["left"]["bytes_per_particle"],
               br = s["sets"]["right"]["bytes_per_particle"];
  std::printf("bytes per particle: left (mohr_coulomb) %zu, right (linear_elastic) %zu\n", bl, br);
  CHECK(bl == br + sizeof(double));  // one scalar state field more
  CHECK_FALSE(fs::exists(out / "particles.xdmf"));
}

TEST_CASE("a probe follows a particle of the set it names", "[sets]") {
  TempDir dir("sets_probe");
  const std::string yaml =
      split_collapse(true) +
      "probes:\n"
      "  - {name: r, set: right, particle_near: [0.05, 0.2], fields: [position]}\n"
      "  - {name: l, particle_near: [0.05, 0.2], fields: [position]}\n";
  auto r = run_yaml(dir.path, yaml, "--threads 1 --set time.end=0.01");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto pr = read_csv_columns(dir.path / "out/probe_r.csv");
  const auto pl = read_csv_columns(dir.path / "out/probe_l.csv");
  REQUIRE(!pr.at("position_x").empty());
  // The nearest particle of `right` to x = 0.05 is in its first column (x = 0.105); the default
  // set (the first, `left`) has one at x = 0.045 or 0.055.
  std::printf("probe in set right starts at x = %.4f, in the default set at x = %.4f\n",
              pr.at("position_x")[0], pl.at("position_x")[0]);
  CHECK(std::fabs(pr.at("position_x")[0] - 0.105) < 1e-12);
  CHECK(std::fabs(pl.at("position_x")[0] - 0.05) < 0.0051);
}

TEST_CASE("bad particle-set input: located errors listing the valid sets, exit 2",
          "[sets][bad_config]") {
  struct Case {
    std::string what, yaml, expect;
  };
  const std::string ok = split_collapse(true);
  auto replace = [](std::string s, const std::string& a, const std::string& b) {
    const size_t k = s.find(a);
    REQUIRE(k != std::string::npos);
    return s.replace(k, a.size(), b);
  };
  const std::vector<Case> cases = {
      {"unknown set on a body", replace(ok, "    set: right\n", "    set: rigth\n"),
       ":13:10: error: bodies.1.set: unknown particle set 'rigth'; scheme 'single_phase' has: "
       "left (material points on the one velocity field), right (material points on the one "
       "velocity field)"},
      {"a set the two-phase scheme does not have",
       "grid: {extent: [1], cell_size: 0.1}\n"
       "scheme: {type: two_phase_single_point, porosity: 0.4, drag: {type: darcy, "
       "hydraulic_conductivity: 1e-3}}\n"
       "bodies:\n"
       "  - {name: soil, set: liquid, generator: {type: box, min: [0], max: [1]}, material: {type: "
       "linear_elastic, E: 1e7, nu: 0, density: 2650}}\n"
       "time: {end: 0.01}\n",
       ":4:23: error: bodies.0.set: unknown particle set 'liquid'; scheme "
       "'two_phase_single_point' has: particles (points of the saturated mixture: the "
       "skeleton carrying its pore water)"},
      {"duplicate set names", replace(ok, "sets: [left, right]", "sets: [left, left]"),
       "error: scheme.sets.1: duplicate set name 'left'"},
      {"a set name that is not a file name",
       replace(ok, "sets: [left, right]", "sets: [left, \"a/b\"]"),
       "error: scheme.sets.1: a set name names its output files"},
      {"unknown set on a probe",
       ok + "probes:\n  - {name: p, set: middle, particle_near: [0.05, 0.2], fields: [position]}\n",
       "error: probes.0.set: unknown particle set 'middle'"},
  };
  for (const auto& c : cases) {
    TempDir dir("sets_bad");
    auto r = run_yaml(dir.path, c.yaml, "--threads 1");
    std::printf("%s: exit %d: %s", c.what.c_str(), r.exit_code, r.output.c_str());
    CHECK(r.exit_code == 2);
    CHECK(r.output.find(c.expect) != std::string::npos);
    CHECK_FALSE(fs::exists(dir.path / "out"));
  }
}
