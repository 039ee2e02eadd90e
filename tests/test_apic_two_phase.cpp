// APIC in the two-phase schemes (issue 17, deliverable 1; framework/affine_transfer.hpp). The
// single-point scheme (schemes/two_phase_single_point.cpp): each particle carries B_p of the
// solid and of the water velocity; the double-point scheme (schemes/two_phase_double_point.cpp):
// each solid or liquid point carries B_p of its own phase's velocity. A saturated disk spinning
// freely keeps the mixture's angular momentum (PIC loses it); the Terzaghi column
// (docs/verification.md C) gives the same consolidation with APIC as with FLIP; a rigid translation
// gives no stress or pore pressure; bad input gives located errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <string>

#include "cli.hpp"
#include "sim_helpers.hpp"

namespace {

constexpr double kOmega = 1.0, kCentre = 1.0;

/// A free saturated elastic disk of radius 0.5 m about (1, 1), no gravity, no boundaries.
std::string saturated_disk(const std::string& shape, const std::string& scheme,
                           const std::string& Kw = "2.0e7") {
  return "grid: {extent: [2, 2], cell_size: 0.1}\n"
         "gravity: [0, 0]\n"
         "shape_function: " +
         shape +
         "\nscheme: {type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: " + Kw +
         ", drag: {type: darcy, hydraulic_conductivity: 1.0e-3}" + scheme +
         "}\n"
         "bodies:\n"
         "  - name: disk\n"
         "    generator: {type: sphere, center: [1, 1], radius: 0.5}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}\n"
         "time: {end: 100, cfl: 0.5}\n";
}

/// A particle's water mass and position at the start of a step, by id.
struct Start {
  double mw, x, y;
};

/// Angular momentum about the centre of solid and water, each with its affine share
/// m (B_yx - B_xy) (Jiang et al. 2015). The water mass of a particle is n rho_w V and its
/// position the current one, or, when `start` is given, those it holds for the particle's id.
double angular_momentum(loam::Simulation<2>& sim,
                        const std::map<uint32_t, Start>* start = nullptr) {
  auto& P = sim.sets[0].particles;
  const int w = P.find("water_velocity"), n = P.find("porosity");
  const int Bs = P.find("affine_moment"), Bw = P.find("water_affine_moment");
  double L = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    const Start s = start ? start->at(P.id[i])
                          : Start{P.col(n)[i] * 1000 * P.col(P.volume)[i], P.col(P.position, 0)[i],
                                  P.col(P.position, 1)[i]};
    const double x = s.x - kCentre, y = s.y - kCentre, ms = P.col(P.mass)[i], mw = s.mw;
    L += ms * (x * P.col(P.velocity, 1)[i] - y * P.col(P.velocity, 0)[i]);
    L += mw * (x * P.col(w, 1)[i] - y * P.col(w, 0)[i]);
    if (Bs >= 0)
      L += ms * (P.col(Bs, 2)[i] - P.col(Bs, 1)[i]) + mw * (P.col(Bw, 2)[i] - P.col(Bw, 1)[i]);
  }
  return L;
}

struct Spin {
  double drift = 0;     // |L_end / L_1 - 1|
  double per_step = 0;  // largest |L_after - L_before| / |L_1| of one step at fixed water masses
};

/// Spin the disk (both phases) at kOmega, then `steps` steps. Each step's transfers and grid
/// update are checked at the water masses and positions of its P2G (the step's start, by id):
/// the single-point formulation then moves the water with the solid velocity (x_p x m_w w
/// changes by dt v x m_w w where w differs from v) and its water mass n rho_w V follows the
/// porosity and volume, not conserved per particle; those move L between steps.
Spin spin(const std::string& shape, const std::string& scheme, int steps) {
  auto sim = loam_test::make_simulation<2>(saturated_disk(shape, scheme));
  auto& P = sim->sets[0].particles;
  const int w = P.find("water_velocity"), n = P.find("porosity");
  for (size_t i = 0; i < P.size(); ++i) {
    const double vx = -kOmega * (P.col(P.position, 1)[i] - kCentre),
                 vy = kOmega * (P.col(P.position, 0)[i] - kCentre);
    P.col(P.velocity, 0)[i] = P.col(w, 0)[i] = vx;
    P.col(P.velocity, 1)[i] = P.col(w, 1)[i] = vy;
  }
  loam_test::advance(*sim, 1);
  const double L1 = angular_momentum(*sim);
  Spin r;
  for (int s = 0; s < steps; ++s) {
    std::map<uint32_t, Start> mw;
    for (size_t i = 0; i < P.size(); ++i)
      mw[P.id[i]] = {P.col(n)[i] * 1000 * P.col(P.volume)[i], P.col(P.position, 0)[i],
                     P.col(P.position, 1)[i]};
    const double before = angular_momentum(*sim, &mw);
    loam_test::advance(*sim, 1);
    r.per_step =
        std::max(r.per_step, std::fabs(angular_momentum(*sim, &mw) - before) / std::fabs(L1));
  }
  r.drift = std::fabs(angular_momentum(*sim) / L1 - 1);
  return r;
}

}  // namespace

TEST_CASE("apic two-phase: a spinning saturated disk keeps its angular momentum, PIC loses it",
          "[apic][transfer][two_phase]") {
  // Both phases' transfers conserve angular momentum, the drag is an equal and opposite pair at
  // each node and the stresses are symmetric: at the water masses and positions of the step's
  // P2G, each step keeps the mixture's angular momentum to round-off (target 1e-12 of L per
  // step, 500 steps, APIC with MUSL and USL). The single-point formulation's move (the water
  // rides on the solid's velocity) and its water mass n rho_w V (not conserved per particle)
  // move L between steps: the drift over the 500 steps is printed beside pure FLIP's, and PIC's
  // (target above 0.5).
  for (const char* update : {"musl", "usl"})
    for (const char* shape : {"gimp", "bspline2"}) {
      const std::string u = std::string(", update: ") + update;
      const auto apic = spin(shape, u + ", transfer: apic", 500);
      const auto flip = spin(shape, u, 500);
      const auto pic = spin(shape, u + ", flip: 0", 500);
      std::printf(
          "saturated spinning disk, %s, update %s, 500 steps: APIC per-step change %.2e, drift "
          "%.2e; FLIP per-step %.2e, drift %.2e; PIC drift %.2e\n",
          shape, update, apic.per_step, apic.drift, flip.per_step, flip.drift, pic.drift);
      CHECK(apic.per_step < 1e-12);
      CHECK(pic.drift > 0.5);
    }
}

TEST_CASE("apic two-phase: the Terzaghi column consolidates as with FLIP",
          "[apic][transfer][two_phase][verification]") {
  // configs/seed001_terzaghi.yaml (docs/verification.md C) with gimp, FLIP against APIC: both
  // within the 0.03 p0 of the series at every sampled time factor, and within 0.005 p0 of
  // each other (a 1D column at rest but for the consolidation: the transfers barely differ).
  loam_test::TempDir f("terzaghi_flip_gimp"), a("terzaghi_apic_gimp");
  const std::string base = "--threads 1 --set shape_function=gimp";
  const auto sf = loam_test::run_scene("seed001_terzaghi.yaml", f.path, base);
  const auto sa =
      loam_test::run_scene("seed001_terzaghi.yaml", a.path, base + " --set scheme.transfer=apic");
  const double ef = sf["verify"]["max_error"], ea = sa["verify"]["max_error"];
  std::printf("terzaghi column, gimp: max |p - p_ref| / p0 FLIP %.4f, APIC %.4f\n", ef, ea);
  CHECK(ef <= 0.03);
  CHECK(ea <= 0.03);
  CHECK(std::fabs(ea - ef) <= 0.005);
}

TEST_CASE("apic two-phase: a rigid translation gives no stress and no pore pressure",
          "[apic][transfer][two_phase][invariance]") {
  // A free saturated block translating at 1 m/s (both phases) across 10 cells: B_p stays zero
  // and no effective stress or pore pressure appears. Targets: |sigma'|, |p| < 1e-6 Pa,
  // |v - 1|, |w - 1| < 1e-12 m/s.
  for (const char* shape : {"gimp", "bspline2", "cpdi"}) {
    auto sim = loam_test::make_simulation<2>(
        std::string("grid: {extent: [3, 1], cell_size: 0.1}\ngravity: [0, 0]\nshape_function: ") +
        shape +
        "\nscheme: {type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: 2.0e7, "
        "transfer: apic, drag: {type: "
        "darcy, hydraulic_conductivity: 1.0e-3}}\nbodies:\n  - name: b\n    generator: {type: "
        "box, min: [0.5, 0.3], max: [1.3, 0.7]}\n    particles_per_cell: 2\n    velocity: [1, "
        "0]\n    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}\n"
        "time: {end: 10, cfl: 0.5}\n");
    auto& P = sim->sets[0].particles;
    const int w = P.find("water_velocity"), pw = P.find("pore_pressure");
    const double x0 = P.col(P.position, 0)[0];
    double dv = 0, sig = 0;
    for (int n = 0; n < 20000 && P.col(P.position, 0)[0] - x0 < 1.0; ++n) {
      loam_test::advance(*sim, 1);
      for (size_t i = 0; i < P.size(); ++i) {
        dv = std::max({dv, std::fabs(P.col(P.velocity, 0)[i] - 1), std::fabs(P.col(w, 0)[i] - 1)});
        sig = std::max(sig, std::fabs(P.col(pw)[i]));
        for (int c = 0; c < P.NS; ++c) sig = std::max(sig, std::fabs(P.col(P.stress, c)[i]));
      }
    }
    const double moved = P.col(P.position, 0)[0] - x0;
    std::printf(
        "saturated rigid translation, APIC, %s, %.2f m: max |v - 1| %.2e m/s, max "
        "|sigma'|, |p| %.2e Pa\n",
        shape, moved, dv, sig);
    CHECK(moved >= 1.0);
    CHECK(dv < 1e-12);
    CHECK(sig < 1e-6);
  }
}

TEST_CASE("apic two-phase: bad transfer input gives located errors",
          "[apic][transfer][two_phase][bad_config]") {
  namespace fs = std::filesystem;
  loam_test::TempDir dir("apic_two_phase_bad");
  fs::create_directories(dir.path);
  struct Case {
    std::string shape, extra, message;
  };
  const Case cases[] = {
      {"linear", "transfer: apic", "scheme.transfer: transfer: apic in this scheme needs gimp"},
      {"gimp", "transfer: apic, flip: 0.98",
       "scheme.flip: flip blends FLIP and PIC; transfer: apic replaces both"},
      {"gimp", "transfer: tpic", "scheme.transfer: unknown value 'tpic'"},
  };
  for (const auto& c : cases) {
    fs::remove_all(dir.path / "out");
    const std::string yaml =
        "grid: {extent: [1, 1], cell_size: 0.25}\nscheme: {type: two_phase_single_point, "
        "porosity: 0.4, drag: {type: darcy, hydraulic_conductivity: 1.0e-3}, " +
        c.extra + "}\nshape_function: " + c.shape +
        "\nbodies:\n  - name: b\n    generator: {type: box, min: [0, 0], max: [0.5, 0.5]}\n"
        "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}\n"
        "time: {end: 0.1}\n";
    const auto r = loam_test::run_yaml(dir.path, yaml);
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.find("run.yaml:2:") != std::string::npos);
    CHECK(r.output.find(c.message) != std::string::npos);
    CHECK(!fs::exists(dir.path / "out"));
  }
}

namespace {

/// A free saturated disk in the double-point scheme: solid points (elastic) and liquid points
/// (water, K_w = 20 MPa) at the same places, radius 0.5 m about (1, 1), no gravity.
std::string double_point_disk(const std::string& shape, const std::string& scheme) {
  return "grid: {extent: [2, 2], cell_size: 0.1}\ngravity: [0, 0]\nshape_function: " + shape +
         "\nscheme: {type: two_phase_double_point, porosity: 0.4, drag: {type: darcy, "
         "hydraulic_conductivity: 1.0e-3}" +
         scheme +
         "}\nbodies:\n"
         "  - {name: grains, set: solid, generator: {type: sphere, center: [1, 1], radius: 0.5}, "
         "material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}}\n"
         "  - {name: water, set: liquid, generator: {type: sphere, center: [1, 1], radius: 0.5}, "
         "material: {type: newtonian_fluid, bulk_modulus: 2.0e7, viscosity: 1.0e-3, density: "
         "1000}}\n"
         "time: {end: 100, cfl: 0.5}\n";
}

/// Angular momentum about the centre of every point of both sets, with its affine share; with
/// `start`, each point's mass and position are those it had at the step's start (by set and id).
double angular_momentum_dp(loam::Simulation<2>& sim,
                           const std::map<std::pair<int, uint32_t>, Start>* start = nullptr) {
  double L = 0;
  for (int k = 0; k < 2; ++k) {
    auto& P = sim.sets[size_t(k)].particles;
    const int B = P.find("affine_moment");
    for (size_t i = 0; i < P.size(); ++i) {
      const Start s =
          start ? start->at({k, P.id[i]})
                : Start{P.col(P.mass)[i], P.col(P.position, 0)[i], P.col(P.position, 1)[i]};
      const double x = s.x - kCentre, y = s.y - kCentre;
      L += s.mw * (x * P.col(P.velocity, 1)[i] - y * P.col(P.velocity, 0)[i]);
      if (B >= 0) L += s.mw * (P.col(B, 2)[i] - P.col(B, 1)[i]);
    }
  }
  return L;
}

Spin spin_double_point(const std::string& shape, const std::string& scheme, int steps) {
  auto sim = loam_test::make_simulation<2>(double_point_disk(shape, scheme));
  for (auto& set : sim->sets) {
    auto& P = set.particles;
    for (size_t i = 0; i < P.size(); ++i) {
      P.col(P.velocity, 0)[i] = -kOmega * (P.col(P.position, 1)[i] - kCentre);
      P.col(P.velocity, 1)[i] = kOmega * (P.col(P.position, 0)[i] - kCentre);
    }
  }
  loam_test::advance(*sim, 1);
  const double L1 = angular_momentum_dp(*sim);
  Spin r;
  for (int s = 0; s < steps; ++s) {
    std::map<std::pair<int, uint32_t>, Start> start;
    for (int k = 0; k < 2; ++k) {
      auto& P = sim->sets[size_t(k)].particles;
      for (size_t i = 0; i < P.size(); ++i)
        start[{k, P.id[i]}] = {P.col(P.mass)[i], P.col(P.position, 0)[i], P.col(P.position, 1)[i]};
    }
    const double before = angular_momentum_dp(*sim, &start);
    loam_test::advance(*sim, 1);
    r.per_step =
        std::max(r.per_step, std::fabs(angular_momentum_dp(*sim, &start) - before) / std::fabs(L1));
  }
  r.drift = std::fabs(angular_momentum_dp(*sim) / L1 - 1);
  return r;
}

}  // namespace

TEST_CASE("apic double point: a spinning saturated disk keeps its angular momentum",
          "[apic][transfer][double_point]") {
  // Solid and liquid points each carry B_p of their phase's velocity; both transfers, the drag
  // pair at each node and the symmetric stresses keep the total angular momentum. Checked per
  // step at the masses and positions of the step's P2G (target 1e-12 of L, 300 steps), and over
  // the run against FLIP and PIC (PIC: above 0.5).
  for (const char* shape : {"gimp", "bspline2"}) {
    const auto apic = spin_double_point(shape, ", transfer: apic", 300);
    const auto flip = spin_double_point(shape, "", 300);
    const auto pic = spin_double_point(shape, ", flip: 0", 300);
    std::printf(
        "double-point spinning disk, %s, 300 steps: APIC per-step change %.2e, drift %.2e; "
        "FLIP per-step %.2e, drift %.2e; PIC drift %.2e\n",
        shape, apic.per_step, apic.drift, flip.per_step, flip.drift, pic.drift);
    CHECK(apic.per_step < 1e-12);
    CHECK(pic.drift > 0.5);
  }
}

TEST_CASE("apic double point: the Terzaghi column consolidates as with FLIP",
          "[apic][transfer][double_point][verification]") {
  // configs/terzaghi_double_point.yaml (docs/verification.md F, target 0.03 p0), FLIP against
  // APIC with gimp: both within the target, and within 0.005 p0 of each other.
  loam_test::TempDir f("terzaghi_dp_flip"), a("terzaghi_dp_apic");
  const std::string base = "--threads 1 --set shape_function=gimp";
  const auto sf = loam_test::run_scene("terzaghi_double_point.yaml", f.path, base);
  const auto sa = loam_test::run_scene("terzaghi_double_point.yaml", a.path,
                                       base + " --set scheme.transfer=apic");
  const double ef = sf["verify"]["max_error"], ea = sa["verify"]["max_error"];
  std::printf("double-point terzaghi column, gimp: max |p - p_ref| / p0 FLIP %.4f, APIC %.4f\n", ef,
              ea);
  CHECK(ef <= 0.03);
  CHECK(ea <= 0.03);
  CHECK(std::fabs(ea - ef) <= 0.005);
}

TEST_CASE("apic double point: linear tents are a located error",
          "[apic][transfer][double_point][bad_config]") {
  namespace fs = std::filesystem;
  loam_test::TempDir dir("apic_double_point_bad");
  fs::create_directories(dir.path);
  const auto r = loam_test::run_yaml(
      dir.path,
      "grid: {extent: [1, 1], cell_size: 0.25}\nscheme: {type: two_phase_double_point, porosity: "
      "0.4, drag: {type: darcy, hydraulic_conductivity: 1.0e-3}, transfer: apic}\nbodies:\n  - "
      "{name: b, set: solid, generator: {type: box, min: [0, 0], max: [0.5, 0.5]}, material: "
      "{type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}}\ntime: {end: 0.1}\n");
  INFO(r.output);
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("run.yaml:2:") != std::string::npos);
  CHECK(r.output.find("scheme.transfer: transfer: apic in this scheme needs gimp") !=
        std::string::npos);
  CHECK(!fs::exists(dir.path / "out"));
}
