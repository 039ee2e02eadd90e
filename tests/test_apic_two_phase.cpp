// APIC in the two-phase schemes (docs/transfers.md; framework/affine_transfer.hpp). The
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
#include "disks.hpp"
#include "sim_helpers.hpp"

namespace {

constexpr double kOmega = 1.0, kCentre = 1.0;

/// The free saturated disk (tests/disks.hpp) under the single-point scheme; `scheme` is
/// appended inside its mapping.
std::string saturated_disk(const std::string& shape, const std::string& scheme) {
  return loam_test::disk_yaml(shape,
                              "type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: "
                              "2.0e7, drag: {type: darcy, hydraulic_conductivity: 1.0e-3}" +
                                  scheme,
                              "2650");
}

/// A point's masses and position at the start of a step: its own mass (P.mass) and, in the
/// single-point scheme, its pore water's n rho_w V.
struct Start {
  double m, mw, x, y;
};
using Starts = std::map<std::pair<size_t, uint32_t>, Start>;  // by set and id

Start start_of(const loam::Particles<2>& P, size_t i) {
  const int w = P.find("water_velocity"), n = P.find("porosity");
  return {P.col(P.mass)[i], w >= 0 ? P.col(n)[i] * 1000 * P.col(P.volume)[i] : 0.0,
          P.col(P.position, 0)[i], P.col(P.position, 1)[i]};
}

/// Angular momentum about the centre of every point of every set: its velocity with its mass
/// and, in the single-point scheme, its water velocity with the water mass, each with its
/// affine share m (B_yx - B_xy) (Jiang et al. 2015). Masses and positions are the current ones,
/// or, with `start`, those of the step's start.
double angular_momentum(loam::Simulation<2>& sim, const Starts* start = nullptr) {
  double L = 0;
  for (size_t k = 0; k < sim.sets.size(); ++k) {
    const auto& P = sim.sets[k].particles;
    const int w = P.find("water_velocity");
    const int Bs = P.find("affine_moment"), Bw = P.find("water_affine_moment");
    for (size_t i = 0; i < P.size(); ++i) {
      const Start s = start ? start->at({k, P.id[i]}) : start_of(P, i);
      const double x = s.x - kCentre, y = s.y - kCentre;
      L += s.m * (x * P.col(P.velocity, 1)[i] - y * P.col(P.velocity, 0)[i]);
      if (Bs >= 0) L += s.m * (P.col(Bs, 2)[i] - P.col(Bs, 1)[i]);
      if (w >= 0) L += s.mw * (x * P.col(w, 1)[i] - y * P.col(w, 0)[i]);
      if (Bw >= 0) L += s.mw * (P.col(Bw, 2)[i] - P.col(Bw, 1)[i]);
    }
  }
  return L;
}

struct Spin {
  double drift = 0;     // |L_end / L_1 - 1|
  double per_step = 0;  // largest |L_after - L_before| / |L_1| of one step at its P2G's masses
};

/// Spin the disk of `yaml` (every phase) at kOmega, then `steps` steps. Each step's transfers
/// and grid update are checked at the masses and positions of its P2G (the step's start, by
/// set and id): the single-point formulation moves the water with the solid velocity (x_p x m_w w
/// changes by dt v x m_w w where w differs from v) and its water mass n rho_w V follows the
/// porosity and volume, not conserved per particle; those move L between steps.
Spin spin(const std::string& yaml, int steps) {
  auto sim = loam_test::make_simulation<2>(yaml);
  loam_test::set_rigid_rotation(*sim, kOmega, kCentre, kCentre);
  loam_test::advance(*sim, 1);
  const double L1 = angular_momentum(*sim);
  Spin r;
  for (int s = 0; s < steps; ++s) {
    Starts start;
    for (size_t k = 0; k < sim->sets.size(); ++k) {
      const auto& P = sim->sets[k].particles;
      for (size_t i = 0; i < P.size(); ++i) start[{k, P.id[i]}] = start_of(P, i);
    }
    const double before = angular_momentum(*sim, &start);
    loam_test::advance(*sim, 1);
    r.per_step =
        std::max(r.per_step, std::fabs(angular_momentum(*sim, &start) - before) / std::fabs(L1));
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
      const auto apic = spin(saturated_disk(shape, u + ", transfer: apic"), 500);
      const auto flip = spin(saturated_disk(shape, u), 500);
      const auto pic = spin(saturated_disk(shape, u + ", flip: 0"), 500);
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
  // within 0.03 p0 (the double-point target of docs/verification.md F) of the series at every
  // sampled time factor, and within 0.005 p0 of each other (a 1D column at rest but for the
  // consolidation: the transfers barely differ).
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
  loam_test::TempDir dir("apic_two_phase_bad");
  struct Case {
    std::string shape, extra, message;
  };
  const Case cases[] = {
      {"linear", "transfer: apic", "scheme.transfer: transfer: apic in this scheme needs gimp"},
      {"gimp", "transfer: apic, flip: 0.98",
       "scheme.flip: flip blends FLIP and PIC; transfer: apic replaces both"},
      {"gimp", "transfer: polypic", "scheme.transfer: unknown value 'polypic'"},
  };
  for (const auto& c : cases)
    loam_test::check_located_error(
        dir.path,
        "grid: {extent: [1, 1], cell_size: 0.25}\nscheme: {type: two_phase_single_point, "
        "porosity: 0.4, drag: {type: darcy, hydraulic_conductivity: 1.0e-3}, " +
            c.extra + "}\nshape_function: " + c.shape +
            "\nbodies:\n  - name: b\n    generator: {type: box, min: [0, 0], max: [0.5, 0.5]}\n"
            "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}\n"
            "time: {end: 0.1}\n",
        "run.yaml:2:", c.message);
}

TEST_CASE("apic double point: a spinning saturated disk keeps its angular momentum",
          "[apic][transfer][double_point]") {
  // Solid and liquid points each carry B_p of their phase's velocity; both transfers, the drag
  // pair at each node and the symmetric stresses keep the total angular momentum. Checked per
  // step at the masses and positions of the step's P2G (target 1e-12 of L, 300 steps), and over
  // the run against FLIP and PIC (PIC: above 0.5).
  for (const char* shape : {"gimp", "bspline2"}) {
    const auto apic = spin(loam_test::double_point_disk_yaml(shape, ", transfer: apic"), 300);
    const auto flip = spin(loam_test::double_point_disk_yaml(shape, ""), 300);
    const auto pic = spin(loam_test::double_point_disk_yaml(shape, ", flip: 0"), 300);
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
  loam_test::TempDir dir("apic_double_point_bad");
  loam_test::check_located_error(
      dir.path,
      "grid: {extent: [1, 1], cell_size: 0.25}\nscheme: {type: two_phase_double_point, porosity: "
      "0.4, drag: {type: darcy, hydraulic_conductivity: 1.0e-3}, transfer: apic}\nbodies:\n  - "
      "{name: b, set: solid, generator: {type: box, min: [0, 0], max: [0.5, 0.5]}, material: "
      "{type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}}\ntime: {end: 0.1}\n",
      "run.yaml:2:", "scheme.transfer: transfer: apic in this scheme needs gimp");
}
