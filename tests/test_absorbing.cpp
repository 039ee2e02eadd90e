// The viscous absorbing boundary (plugins/boundaries/absorbing.cpp, Lysmer & Kuhlemeyer 1969): its
// nodal update against hand values (tributary areas, implicit dashpot, the two-phase impermeable
// form), the reflection of a 1D/2D elastic pulse (single_phase) and of the undrained wave in a
// saturated column (two_phase_single_point) against the same scenes with a fixed face, and its
// located input errors.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "framework/simulation.hpp"
#include "sim_helpers.hpp"

namespace {

// ------------------------------------------------------------------ nodal update, hand values

/// Run the absorbing plugin of a D-dimensional scene on a hand-made grid update and compare
/// every node with v = m v* / (m + dt C), C = rho c A, A the node's tributary face area.
template <int D>
void check_nodal_update(const std::string& yaml, int axis, const std::vector<double>& h,
                        int phases) {
  auto sim = loam_test::make_simulation<D>(yaml);
  const auto& g = sim->grid;
  const double rho = 2000, cp = 300, cs = 150, dt = 1e-3;
  constexpr int S = 1 + 2 * D;  // mass, velocity, acceleration
  std::vector<double> solid(g.num_nodes * S), water(g.num_nodes * S);
  auto fill = [&](std::vector<double>& r, double scale) {
    for (size_t n = 0; n < g.num_nodes; ++n) {
      r[n * S] = scale * (0.5 + 0.01 * double(n));  // masses of order rho c A dt
      for (int d = 0; d < D; ++d) {
        r[n * S + 1 + size_t(d)] = scale * (1.0 + 0.1 * d - 0.03 * double(n));
        r[n * S + 1 + D + size_t(d)] = 7.0 + d;
      }
    }
  };
  fill(solid, 1.0);
  fill(water, 0.3);
  const auto solid0 = solid, water0 = water;
  loam::GridUpdate u;
  u.phases[0] = {loam::NodalVector{solid.data(), S, 1}, loam::NodalVector{solid.data(), S, 1 + D},
                 loam::NodalVector{solid.data(), S, 0}};
  u.phases[1] = {loam::NodalVector{water.data(), S, 1}, loam::NodalVector{water.data(), S, 1 + D},
                 loam::NodalVector{water.data(), S, 0}};
  u.count = phases;
  u.dt = dt;
  sim->boundaries.at(0)->constrain_grid_update(u);
  double worst = 0;
  int on_face = 0, untouched = 0;
  for (size_t n = 0; n < g.num_nodes; ++n) {
    const auto ijk = g.node_ijk(n);
    const bool face = ijk[size_t(axis)] == 0;  // the tests use the lower face of `axis`
    double A = 1;
    for (int d = 0; d < D; ++d)
      if (d != axis) {
        const bool edge = ijk[size_t(d)] == 0 || ijk[size_t(d)] == g.nodes[size_t(d)] - 1;
        A *= h[size_t(d)] * (edge ? 0.5 : 1.0);
      }
    on_face += face;
    const double ms = solid0[n * S], mw = water0[n * S];
    for (int d = 0; d < D; ++d) {
      const size_t v = n * S + 1 + size_t(d), a = v + D;
      double vs = solid0[v], vw = water0[v];
      if (face) {
        const double C = rho * (d == axis ? cp : cs) * A;
        if (phases == 2 && d == axis) {
          vs = vw = (ms * solid0[v] + mw * water0[v]) / (ms + mw + dt * C);
        } else {
          vs = ms * solid0[v] / (ms + dt * C);  // water tangential: untouched
        }
      }
      untouched += !face && solid[v] == solid0[v] && solid[a] == solid0[a];
      worst = std::max({worst, std::fabs(solid[v] - vs), std::fabs(water[v] - vw),
                        std::fabs(solid[a] - (solid0[a] + (vs - solid0[v]) / dt)),
                        std::fabs(water[a] - (water0[a] + (vw - water0[v]) / dt))});
    }
  }
  std::printf("absorbing nodal update %dD, %d phase(s): %d face nodes, max deviation %.2e\n", D,
              phases, on_face, worst);
  CHECK(worst < 1e-12);
  CHECK(untouched == int(g.num_nodes - size_t(on_face)) * D);
}

}  // namespace

TEST_CASE("absorbing: implicit dashpots with tributary face areas, hand values",
          "[boundary][unit]") {
  // Reference: the plugin's equations (plugins/boundaries/absorbing.cpp header): v = m v*/(m + dt
  // rho c A) per component (c_p normal, c_s tangential), a += (v - v*)/dt; two phases: common
  // normal velocity (m_s v_s* + m_w v_w*)/(m_s + m_w + dt rho c_p A), water tangential untouched.
  // A: 1 in 1D; h or h/2 (grid edge) in 2D; h1 h2, /2 on an edge, /4 at a corner in 3D. Nodes off
  // the face are not touched. Tolerance 1e-12 (rounding of O(1) values).
  auto scene = [](const std::string& grid, const std::string& lo, const std::string& hi,
                  const std::string& face, bool shear) {
    return "grid: " + grid + "\nbodies:\n  - name: b\n    generator: {type: box, min: " + lo +
           ", max: " + hi +
           "}\n    material: {type: linear_elastic, E: 1.0e7, nu: 0.2, density: 2000}\n"
           "time: {end: 1}\nboundaries:\n  - {type: absorbing, face: " +
           face + ", density: 2000, p_wave_speed: 300" + (shear ? ", s_wave_speed: 150" : "") +
           "}\n";
  };
  for (int phases : {1, 2}) {
    check_nodal_update<1>(scene("{extent: [1], cell_size: 0.25}", "[0.1]", "[0.2]", "x-", false), 0,
                          {0.25}, phases);
    check_nodal_update<2>(
        scene("{extent: [1, 0.5], cell_size: [0.25, 0.1]}", "[0.1, 0.1]", "[0.2, 0.2]", "y-", true),
        1, {0.25, 0.1}, phases);
    check_nodal_update<3>(scene("{extent: [0.5, 0.4, 0.6], cell_size: [0.25, 0.1, 0.2]}",
                                "[0.1, 0.1, 0.1]", "[0.2, 0.2, 0.2]", "z-", true),
                          2, {0.25, 0.1, 0.2}, phases);
  }
}

// ------------------------------------------------------------------ single phase: elastic pulse

namespace {

struct Reflection {
  double incident = 0, reflected = 0, energy_left = 0;
  double ratio() const { return reflected / incident; }
};

/// A half-sine stress pulse of length 1 m (v = v0 sin(pi x), sigma = -rho c v on [0, 1]: a wave
/// travelling in +x only) in a bar [0, 4] m, E = 100 Pa, rho = 1 kg/m^3 (c = 10 m/s), free at
/// x = 0, with `face_bc` on x+. A particle probe at x = 2.5 sees the incident pulse (peak at
/// t = 0.2 s) and the reflected one (peak at t = 0.5 s); split at t = 0.35 s, when the pulse
/// centre reaches the end. Energy from history.csv at t = 0.6 s (pulse gone or back) over t = 0.
Reflection pulse(int D, const std::string& face_bc, const std::string& extra) {
  loam_test::TempDir dir("absorbing_pulse");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "run.yaml";
  const bool two = D == 2;
  auto vec = [&](const std::string& x, const std::string& y) {
    return "[" + x + (two ? ", " + y : "") + "]";
  };
  const std::string k = vec("3.141592653589793", "0");
  const std::string mat = "    material: {type: linear_elastic, E: 100, nu: 0, density: 1}\n";
  std::ofstream(cfg) << "grid: {extent: " << vec("4", "0.2") << ", cell_size: 0.05}\n"
                     << "bodies:\n  - name: pulse\n    generator: {type: box, min: "
                     << vec("0", "0") << ", max: " << vec("1", "0.2") << "}\n"
                     << mat << "    velocity: {type: sine, amplitude: " << vec("0.01", "0")
                     << ", wavenumber: " << k << "}\n"
                     << "    stress: {type: sine, amplitude: [-0.1, 0, 0" << (two ? ", 0" : "")
                     << "], wavenumber: " << k << "}\n"
                     << "  - name: bar\n    generator: {type: box, min: " << vec("1", "0")
                     << ", max: " << vec("4", "0.2") << "}\n"
                     << mat << "boundaries:\n  - " << face_bc << "\n"
                     << (two ? "  - {type: slip, face: y-}\n  - {type: slip, face: y+}\n" : "")
                     << "time: {end: 0.6, cfl: 0.5}\noutput: {every_time: 1, history_every: 1}\n"
                     << "probes:\n  - {name: mid, particle_near: " << vec("2.5", "0.1")
                     << ", fields: [stress]}\n";
  auto r = loam_test::run_loam("run " + cfg.string() + " --quiet --threads 1 --out " +
                               (dir.path / "out").string() + " " + extra);
  REQUIRE(r.exit_code == 0);
  auto probe = loam_test::read_csv_columns(dir.path / "out" / "probe_mid.csv");
  auto hist = loam_test::read_csv_columns(dir.path / "out" / "history.csv");
  Reflection out;
  const auto& t = probe["time"];
  const auto& s = probe["stress_xx"];
  for (size_t i = 0; i < t.size(); ++i)
    (t[i] < 0.35 ? out.incident : out.reflected) =
        std::max(t[i] < 0.35 ? out.incident : out.reflected, std::fabs(s[i]));
  out.energy_left = hist["total_energy"].back() / hist["total_energy"].front();
  return out;
}

}  // namespace

TEST_CASE("absorbing: an elastic pulse leaves a bar through the absorbing end",
          "[boundary][verification]") {
  // Reference: Lysmer-Kuhlemeyer at normal incidence matches the bar's impedance rho c = 10, so
  // the exact reflection is zero; a fixed end reflects the whole pulse (same sign, R = 1, energy
  // kept). Pulse 20 cells long (h = 0.05 m, 2 particles per cell). Targets: reflected peak stress
  // < 5 % of the incident one and < 1 % of the energy left in the bar; fixed end: R > 0.95 and
  // > 99 % of the energy left. Measured (linear): R = 0.026, energy 0.2 %; fixed R = 1.046.
  const std::string absorbing = "{type: absorbing, face: x+, density: 1, p_wave_speed: 10}";
  for (const char* sf : {"linear", "gimp", "bspline2", "cpdi"}) {
    const std::string set = std::string("--set shape_function=") + sf;
    const Reflection a = pulse(1, absorbing, set), f = pulse(1, "{type: fixed, face: x+}", set);
    std::printf(
        "absorbing 1D pulse (%s): incident %.4f Pa, reflected %.5f Pa, R = %.4f, energy left "
        "%.2e; fixed end: R = %.4f, energy left %.4f\n",
        sf, a.incident, a.reflected, a.ratio(), a.energy_left, f.ratio(), f.energy_left);
    CHECK(a.ratio() < 0.05);
    CHECK(a.energy_left < 0.01);
    CHECK(f.ratio() > 0.95);
    CHECK(f.energy_left > 0.99);
  }
  // 2D plane strain strip 0.2 m wide with slip sides: the same plane wave; the face nodes'
  // tributary lengths (h, h/2 at the corners) must give the 1D answer (same target).
  const Reflection a2 =
      pulse(2, "{type: absorbing, face: x+, density: 1, p_wave_speed: 10, s_wave_speed: 7.07}", "");
  std::printf("absorbing 2D pulse: R = %.4f, energy left %.2e\n", a2.ratio(), a2.energy_left);
  CHECK(a2.ratio() < 0.05);
  CHECK(a2.energy_left < 0.01);
}

// ------------------------------------------------------------------ two phase: undrained wave

namespace {

/// Pore pressure at a particle 0.5 m below the drained top of the seed 002 column (undrained
/// P-wave c_u = 656 m/s) under a 1 kPa load ramped over 0.5 ms, sampled every step up to
/// 3.7 ms: the wave reflected at the base (1 m below the top) passes the probe from 2.3 ms;
/// the next one, reflected again at the top, would arrive at 3.8 ms.
std::vector<double> column_probe(const std::string& config, double height, double kappa) {
  loam_test::TempDir dir("absorbing_column");
  char set[512];
  std::snprintf(set, sizeof set,
                "--threads 1 --set loads.0.ramp_time=5e-4 --set time.end=0.0037 --set "
                "probes.0.every_steps=1 --set probes.0.particle_near=[%g] --set grid.extent=[%g] "
                "--set bodies.0.generator.max=[%g] --set scheme.drag.intrinsic_permeability=%g "
                "--set output.every_time=1",
                height - 0.5, height, height, kappa);
  loam_test::run_scene(config, dir.path, set);
  return loam_test::read_csv_columns(dir.path / "probe_base.csv")["pore_pressure"];
}

/// Reflection coefficient: max |p - p_ref| / max |p_ref| over the window, with p_ref from a 2 m
/// column (its base reflection reaches the probe only at 5.3 ms). Same time steps in all runs.
double reflection(const std::vector<double>& p, const std::vector<double>& ref) {
  REQUIRE(p.size() == ref.size());
  double d = 0, m = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    d = std::max(d, std::fabs(p[i] - ref[i]));
    m = std::max(m, std::fabs(ref[i]));
  }
  return d / m;
}

}  // namespace

TEST_CASE("absorbing: the undrained wave leaves a saturated column through an absorbing base",
          "[boundary][verification][two_phase]") {
  // Reference: the seed 002 column (configs/seed002_dynamic_consolidation*.yaml; kappa = 1e-10
  // m^2, drag time rho_w kappa/(n mu_w) ~ 0.3 ms against a 0.5 ms load ramp: nearly undrained),
  // base impermeable either way. A fixed base reflects the wave (pore pressure doubles, R ~ 1);
  // the absorbing base, matched to the undrained impedance rho_sat c_u, should not. Target:
  // R < 0.05 absorbing, R > 0.8 fixed (the window ends before the reflected ramp is complete
  // everywhere). Measured: 0.025 and 0.90. With 100x the permeability (kappa = 1e-8 m^2) the
  // wave is no longer undrained and the undrained impedance is not matched: measured R = 0.072
  // (fixed 1.01); guarded at 0.1, a regression bound on that documented limitation, not a target.
  for (double kappa : {1e-10, 1e-8}) {
    const auto ref = column_probe("seed002_dynamic_consolidation.yaml", 2.0, kappa);
    const double rf =
        reflection(column_probe("seed002_dynamic_consolidation.yaml", 1.0, kappa), ref);
    const double ra =
        reflection(column_probe("seed002_dynamic_consolidation_absorbing.yaml", 1.0, kappa), ref);
    std::printf(
        "absorbing two-phase column, kappa = %g m^2: R = %.4f (absorbing base), %.4f (fixed)\n",
        kappa, ra, rf);
    CHECK(rf > 0.8);
    CHECK(ra < (kappa < 1e-9 ? 0.05 : 0.1));
  }
}

// ------------------------------------------------------------------ input errors

TEST_CASE("absorbing: bad parameters give the located error", "[boundary][cli]") {
  // Reference: the standard FILE:LINE:COL: error: path: message, exit code 2, nothing written.
  loam_test::TempDir dir("absorbing_bad");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "run.yaml";
  struct Case {
    std::string grid, bc, line;
  };
  const std::string g1 = "[4]", g2 = "[4, 1]";
  const std::vector<Case> cases = {
      {g1, "{type: absorbing, face: y-, density: 1, p_wave_speed: 10}",
       ":9:29: error: boundaries.0.face: face 'y-' does not exist in 1D (faces: x-, x+)"},
      {g1, "{type: absorbing, face: q+, density: 1, p_wave_speed: 10}",
       ":9:29: error: boundaries.0.face: unknown value 'q+'; did you mean 'x+'? valid values are: "
       "x-, x+, y-, y+, z-, z+"},
      {g1, "{type: absorbing, face: x+, density: -1, p_wave_speed: 10}",
       ":9:42: error: boundaries.0.density: -1 is out of range (0, inf) kg/m^3"},
      {g1, "{type: absorbing, face: x+, density: 1, p_wave_speed: -10}",
       ":9:59: error: boundaries.0.p_wave_speed: -10 is out of range (0, inf) m/s"},
      {g1, "{type: absorbing, face: x+, density: 1}",
       ":9:5: error: boundaries.0.p_wave_speed: missing required key 'p_wave_speed' (P-wave speed "
       "c_p"},
      {g2, "{type: absorbing, face: x+, density: 1, p_wave_speed: 10, s_wave_speed: -1}",
       ":9:77: error: boundaries.0.s_wave_speed: -1 is out of range [0, inf) m/s"},
      {g2, "{type: absorbing, face: x+, density: 1, p_wave_speed: 10}",
       ":9:5: error: boundaries.0.s_wave_speed: missing required key 's_wave_speed' in 2D (S-wave "
       "speed for the tangential dashpots, m/s; 0 for none)"},
  };
  for (const auto& k : cases) {
    const bool two = k.grid == g2;
    std::ofstream(cfg) << "grid:\n  extent: " << k.grid << "\n  cell_size: 1\nbodies:\n"
                       << "  - name: bar\n    generator: {type: box, min: "
                       << (two ? "[0, 0]" : "[0]") << ", max: " << (two ? "[2, 1]" : "[2]") << "}\n"
                       << "    material: {type: linear_elastic, E: 100, nu: 0.3, density: 1}\n"
                       << "boundaries:\n  - " << k.bc << "\ntime:\n  end: 0.1\n";
    auto r = loam_test::run_loam("run " + cfg.string() + " --quiet --out " +
                                 (dir.path / "out").string());
    std::printf("%s", r.output.c_str());
    CHECK(r.exit_code == 2);
    // The whole output is that one line (the missing-key message continues with its doc text).
    CHECK(r.output.rfind(cfg.string() + k.line, 0) == 0);
    CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
    CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
  }
}

TEST_CASE("absorbing free_field: a geostatic column on an absorbing base stays at rest",
          "[boundary][absorbing]") {
  // A 2D column 4 m tall (rho = 2000, E = 1e7, nu = 0.3) under gravity with its geostatic stress
  // sigma_yy = rho g (y - 4), sigma_xx = K0 sigma_yy (K0 = nu / (1 - nu)), slip sides, the base
  // an absorbing face. A dashpot carries no static load: without free_field the column sinks
  // through it at v = sigma_base / (rho c_p) = 78 480 / (2000 x 82.2) = 0.48 m/s. With
  // free_field the base keeps the reaction of the first step and the column stays at rest to
  // round-off (target max |v| < 1e-9 m/s over 400 steps, measured below) with linear and gimp,
  // whose quadrature balances this state exactly. bspline2's does not near the free top (on a
  // slip base the column moves at up to 4e-4 m/s): the part of its weight the geostatic
  // stress does not carry there (about 0.2 %) is not in the first step's reaction, and a
  // dashpot cannot carry it, so the column still sinks at that fraction of the drift speed.
  // Target there: the mean velocity |p_y| / m below 1 % of the drift speed.
  const double nu = 0.3, k0 = nu / (1 - nu), rho = 2000, g = 9.81;
  const double M = 1e7 * (1 - nu) / ((1 + nu) * (1 - 2 * nu)), cp = std::sqrt(M / rho);
  auto column = [&](int base, const std::string& shape) {  // 0: slip, 1: absorbing, 2: free_field
    char text[2048];
    std::snprintf(
        text, sizeof text,
        "grid: {extent: [1, 4], cell_size: 0.25}\n"
        "gravity: [0, -9.81]\n"
        "shape_function: %s\n"
        "bodies:\n"
        "  - name: soil\n"
        "    generator: {type: box, min: [0, 0], max: [1, 4]}\n"
        "    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}\n"
        "    stress: {type: linear_profile, axis: 1, origin: 4, value: [0, 0, 0, 0], gradient: "
        "[%.17g, %.17g, %.17g, 0]}\n"
        "boundaries:\n"
        "  - {type: slip, face: x-}\n"
        "  - {type: slip, face: x+}\n"
        "  - %s\n"
        "time: {end: 1}\n",
        shape.c_str(), k0 * rho * g, rho * g, k0 * rho * g,
        base == 0
            ? "{type: slip, face: y-}"
            : ("{type: absorbing, face: y-, density: 2000, p_wave_speed: " + std::to_string(cp) +
               ", s_wave_speed: 0, free_field: " + (base == 2 ? "true}" : "false}"))
                  .c_str());
    auto sim = loam_test::make_simulation<2>(text);
    loam_test::advance(*sim, 400);
    const auto& P = sim->sets[0].particles;
    double vmax = 0, p = 0, m = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      vmax = std::max(vmax, std::hypot(P.col(P.velocity, 0)[i], P.col(P.velocity, 1)[i]));
      p += P.col(P.mass)[i] * P.col(P.velocity, 1)[i];
      m += P.col(P.mass)[i];
    }
    return std::pair{vmax, p / m};
  };
  for (const char* shape : {"linear", "gimp", "bspline2"}) {
    const auto [held, mean_held] = column(2, shape);
    const auto [sinking, mean_sinking] = column(1, shape);
    const auto [slip, mean_slip] = column(0, shape);
    const double drift = rho * g * 4 / (rho * cp);
    std::printf(
        "geostatic column on an absorbing base (%s), 400 steps: max |v| %.3e m/s "
        "(mean v_y %+.3e) with free_field, %.3e (mean %+.3e) without (sigma/(rho c_p) = "
        "%.3f m/s), %.3e (mean %+.3e) on a slip base\n",
        shape, held, mean_held, sinking, mean_sinking, drift, slip, mean_slip);
    if (std::string(shape) == "bspline2")
      CHECK(std::fabs(mean_held) < 1e-2 * drift);
    else
      CHECK(held < 1e-9);
    CHECK(sinking > 0.1);
  }
}
