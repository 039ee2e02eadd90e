// The energy balance of history.csv (framework/energy_ledger.hpp): each term measured where it
// acts, and the balance E_kin + E_stored + E_grav + D - W - E_carried - E_0 closing on
// single-phase runs (docs/verification.md, "Energy balance").
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cli.hpp"

namespace fs = std::filesystem;

namespace {

using Columns = std::map<std::string, std::vector<double>>;

/// Runs `yaml` (written to a temporary file, extra CLI arguments appended) and returns its
/// history.csv columns.
Columns run_history(const std::string& name, const std::string& yaml,
                    const std::string& args = "") {
  const fs::path dir = fs::temp_directory_path() / ("loam_energy_" + name);
  fs::create_directories(dir);
  const fs::path cfg = dir / "run.yaml";
  std::ofstream(cfg) << yaml;
  const auto r =
      loam_test::run_loam("run " + cfg.string() + " --out " + (dir / "out").string() +
                          " --overwrite --threads 1 --set output.energy_balance=true " + args);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return loam_test::read_csv_columns(dir / "out" / "history.csv");
}

/// The largest magnitude over the run of the energies (gravity's change) and the balance's
/// terms: the scale the balance is measured against.
double largest_term(const Columns& h) {
  double big = 0;
  const double g0 = h.at("gravity_energy").front();
  for (size_t r = 0; r < h.at("step").size(); ++r) {
    big = std::max({big, std::fabs(h.at("kinetic_energy")[r]), std::fabs(h.at("strain_energy")[r]),
                    std::fabs(h.at("gravity_energy")[r] - g0)});
    for (const char* k : {"dissipation_material", "dissipation_damping", "dissipation_transfer",
                          "dissipation_drag", "work_loads", "work_boundaries", "energy_carried"})
      big = std::max(big, std::fabs(h.at(k)[r]));
  }
  return big;
}

/// The largest |balance| over the run relative to largest_term.
double worst_balance(const Columns& h) {
  double worst = 0;
  for (double b : h.at("energy_balance")) worst = std::max(worst, std::fabs(b));
  return worst / largest_term(h);
}

/// Runs configs/<config> on 1 thread with the energy ledger (extra arguments appended) and
/// returns its history.csv columns.
Columns scene_history(const std::string& config, const std::string& extra = "") {
  const fs::path dir = fs::temp_directory_path() / ("loam_energy_" + config);
  const auto r = loam_test::run_loam("run " + std::string(LOAM_SOURCE_DIR) + "/configs/" + config +
                                     " --quiet --overwrite --out " + dir.string() +
                                     " --threads 1 --set output.energy_balance=true " + extra);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return loam_test::read_csv_columns(dir / "history.csv");
}

const char* kBar = R"(
grid: {origin: [0], extent: [10.5], cell_size: 0.25}
gravity: [0]
shape_function: gimp
bodies:
  - name: bar
    generator: {type: box, min: [0], max: [10]}
    particles_per_cell: 2
    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}
boundaries:
  - {type: fixed, face: x-}
time: {end: 1.0, cfl: 0.5}
output: {every_time: 1.0, history_every: 10}
)";

}  // namespace

TEST_CASE("energy balance: a freely translating body does no work and dissipates nothing",
          "[energy]") {
  // Invariance: a rigid translation (no gravity, no boundary reached) keeps its kinetic energy;
  // every work and dissipation term is zero to round-off, and so is the balance.
  const auto h = run_history("translation", R"(
grid: {origin: [0, 0], extent: [4, 2], cell_size: 0.1}
gravity: [0, 0]
shape_function: gimp
bodies:
  - name: block
    generator: {type: box, min: [0.5, 0.5], max: [1.0, 1.0]}
    particles_per_cell: 2
    material: {type: mohr_coulomb, E: 1.0e6, nu: 0.3, density: 2000, c: 1000, phi: 30, psi: 0}
    velocity: [1.0, 0.0]
time: {end: 1.0, cfl: 0.5}
output: {every_time: 1.0, history_every: 10}
)");
  const double K = h.at("kinetic_energy").front();
  double worst = 0;
  for (const char* k : {"dissipation_material", "dissipation_damping", "dissipation_transfer",
                        "work_loads", "work_boundaries", "energy_carried", "energy_balance"})
    for (double x : h.at(k)) worst = std::max(worst, std::fabs(x));
  std::printf("translating block: kinetic energy %.6g J, largest term or balance %.3g J\n", K,
              worst);
  CHECK(worst <= 1e-9 * K);
}

TEST_CASE("energy balance: a traction's work goes into an elastic bar", "[energy]") {
  // Reference: energy conservation, W_loads = E_kin + E_strain for an elastic bar loaded by a
  // traction (ramped over 0.5 s) on a fixed base; the load's work is sum f . (x^{n+1} - x^n) on
  // the loaded particles. Tolerance: 1 % of the largest term (about 3 500 J).
  const auto h = run_history(
      "traction", std::string(kBar) +
                      "loads:\n  - {type: traction, body: bar, face: x+, traction: [-1.0e5], "
                      "time_function: {type: linear_ramp, duration: 0.5}}\n");
  const double w = h.at("work_loads").back(), rel = worst_balance(h);
  std::printf(
      "traction on an elastic bar (gimp): W_loads %.1f J, E_strain %.1f J, E_kin %.2f J, "
      "D_material %.2f J, largest |balance| %.3f %% of the largest term\n",
      w, h.at("strain_energy").back(), h.at("kinetic_energy").back(),
      h.at("dissipation_material").back(), 100 * rel);
  CHECK(w > 3000);  // the bar was loaded: 1/2 sigma^2 L / M = 3 714 J quasi-statically
  CHECK(rel <= 0.01);
}

TEST_CASE("energy balance: local damping's dissipation is counted", "[energy]") {
  // Reference: energy conservation with dissipation; the bar released from its unloaded state
  // under a suddenly applied traction rings down under local damping (alpha 0.3): D_damping > 0
  // takes what the load put in beyond the strain energy. Tolerance 1 % of the largest term.
  const auto h =
      run_history("damping", std::string(kBar) +
                                 "loads:\n  - {type: traction, body: bar, face: x+, traction: "
                                 "[-1.0e5]}\ndamping: {type: local, alpha: 0.3}\n");
  const double d = h.at("dissipation_damping").back(), rel = worst_balance(h);
  std::printf(
      "damped bar under a sudden traction (gimp): D_damping %.1f J, W_loads %.1f J, "
      "E_strain %.1f J, largest |balance| %.3f %%\n",
      d, h.at("work_loads").back(), h.at("strain_energy").back(), 100 * rel);
  CHECK(d > 0.1 * h.at("strain_energy").back());
  CHECK(rel <= 0.01);
}

TEST_CASE("energy balance: the PIC share of a FLIP/PIC blend is the transfer's dissipation",
          "[energy]") {
  // Reference: energy conservation; a free elastic bar vibrating in its first mode loses
  // kinetic energy to the blend's PIC share (Brackbill & Ruppel 1986), measured at each
  // particle update as 1/2 m (|v_FLIP|^2 - |v|^2). With flip 1 nothing is taken.
  const std::string bar = R"(
grid: {origin: [0], extent: [27], cell_size: 1.0}
gravity: [0]
shape_function: gimp
bodies:
  - name: bar
    generator: {type: box, min: [0], max: [25]}
    particles_per_cell: 2
    material: {type: linear_elastic, E: 100, nu: 0, density: 1}
    velocity: {type: sine, amplitude: [0.1], wavenumber: [0.06283185307179587]}
boundaries:
  - {type: fixed, face: x-}
time: {end: 20, cfl: 0.1}
output: {every_time: 20, history_every: 10}
)";
  const auto flip = run_history("flip", bar);
  const auto blend = run_history("blend", bar, "--set scheme.flip=0.95");
  const double e0 = flip.at("total_energy").front();
  const double d_flip = flip.at("dissipation_transfer").back();
  const double d_blend = blend.at("dissipation_transfer").back();
  const double lost = e0 - blend.at("total_energy").back();
  std::printf(
      "vibrating bar (gimp): D_transfer %.3g J (flip 1), %.4g J (flip 0.95) of the %.4g J "
      "lost; largest |balance| %.3f %% / %.3f %%\n",
      d_flip, d_blend, lost, 100 * worst_balance(flip), 100 * worst_balance(blend));
  CHECK(d_flip == 0.0);
  CHECK(lost > 0.03 * e0);  // the blend damps the mode
  CHECK(std::fabs(d_blend - lost) <= 0.01 * e0);
  CHECK(worst_balance(flip) <= 0.01);
  CHECK(worst_balance(blend) <= 0.01);
}

TEST_CASE("energy balance: plastic work and a prescribed velocity's work", "[energy]") {
  // Reference: energy conservation; a Tresca block (phi = 0) compressed in plane strain by a
  // prescribed velocity on its top row of nodes, on a smooth base beside a smooth wall, free on
  // the other side: the condition's work W_boundaries (its reaction times its velocity) goes
  // into strain energy and plastic dissipation, D_material > 0 once it yields. Tolerance 1 % of
  // the largest term.
  const auto h = run_history("compression", R"(
grid: {origin: [0, 0], extent: [2.0, 1.2], cell_size: 0.1}
gravity: [0, 0]
shape_function: gimp
bodies:
  - name: block
    generator: {type: box, min: [0, 0], max: [1.0, 1.0]}
    particles_per_cell: 2
    material: {type: mohr_coulomb, E: 1.0e6, nu: 0.3, density: 2000, c: 5000, phi: 0, psi: 0}
boundaries:
  - {type: slip, face: y-}
  - {type: slip, face: x-}
  - {type: prescribed_velocity, min: [0, 1.0], max: [1.0, 1.0], velocity: [0, -0.02], directions: [x, y]}
time: {end: 2.0, cfl: 0.5}
output: {every_time: 2.0, history_every: 10}
)");
  const double wb = h.at("work_boundaries").back(), dm = h.at("dissipation_material").back();
  const double rel = worst_balance(h);
  std::printf(
      "compressed Tresca block: W_boundaries %.2f J, D_material %.2f J, E_strain %.2f J, "
      "largest |balance| %.3f %%\n",
      wb, dm, h.at("strain_energy").back(), 100 * rel);
  CHECK(dm > 0.5 * wb);  // mostly dissipated once it flows
  CHECK(rel <= 0.01);
}

TEST_CASE("energy balance: the drag dissipates what consolidation takes from the load",
          "[energy][two_phase]") {
  // Reference: energy conservation in a consolidating column (configs/seed001_terzaghi.yaml,
  // single-point v-w scheme): the load's work goes into the skeleton's strain energy and the
  // drag's dissipation Q |w - v|^2 dt (the pore water's pressure work ends there). Tolerance 1 %
  // of the largest term.
  const auto h = scene_history("seed001_terzaghi.yaml");
  const double w = h.at("work_loads").back(), drag = h.at("dissipation_drag").back();
  const double rel = worst_balance(h);
  std::printf(
      "Terzaghi column: W_loads %.3f J, E_strain %.3f J, D_drag %.3f J, largest |balance| "
      "%.3f %%\n",
      w, h.at("strain_energy").back(), drag, 100 * rel);
  CHECK(drag > 0.4 * w);
  CHECK(rel <= 0.01);
}

TEST_CASE("energy balance: the double-point liquid's pressure work and the drag at held nodes",
          "[energy][two_phase]") {
  // Reference: as the single-point Terzaghi column (configs/terzaghi_double_point.yaml, the same
  // column with solid and liquid points): W_loads = E_strain + D_drag + D_material. The liquid
  // points' stress power is p V times the storage equation's volume rate (the pressure's work on
  // both phases), and the drag dissipates Q |w - v|^2 with the velocities the conditions left
  // (none at the fixed base). Tolerance 1 % of the largest term; the hydrostatic column's drag
  // must be round-off (water at rest over a fixed base).
  const auto h = scene_history("terzaghi_double_point.yaml");
  const double w = h.at("work_loads").back(), drag = h.at("dissipation_drag").back();
  const double rel = worst_balance(h);
  std::printf(
      "Terzaghi column, double point: W_loads %.3f J, E_strain %.3f J, D_drag %.3f J, "
      "D_material %.4f J, largest |balance| %.3f %%\n",
      w, h.at("strain_energy").back(), drag, h.at("dissipation_material").back(), 100 * rel);
  CHECK(drag > 0.4 * w);
  CHECK(std::fabs(h.at("dissipation_material").back()) < 0.01 * w);
  CHECK(rel <= 0.01);

  const auto hs = scene_history("hydrostatic_double_point.yaml", "--set time.end=0.2");
  const double e = hs.at("strain_energy").back();
  std::printf(
      "hydrostatic double point: D_drag %.3g J, largest |balance| %.3g of E_strain %.3f J\n",
      hs.at("dissipation_drag").back(), worst_balance(hs), e);
  CHECK(std::fabs(hs.at("dissipation_drag").back()) < 1e-6 * e);  // 0.027 J counting the base
  CHECK(worst_balance(hs) < 1e-6);
}
