// APIC transfers in the single-phase scheme (docs/transfers.md, docs/verification.md U;
// schemes/single_phase.cpp, Jiang et al. 2015): a free elastic disk spinning about its centre keeps
// its angular momentum to round-off with APIC, with gimp, bspline2 and cpdi, and keeps spinning for
// 10 revolutions; the PIC transfer loses both. Linear tents carry C_p instead of B_p (the scheme's
// header says why): bounded, but angular momentum only nearly kept. Bad input gives located errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cli.hpp"
#include "disks.hpp"
#include "sim_helpers.hpp"

namespace {

constexpr double kOmega = 1.0;  // rad/s
constexpr double kCentre = 1.0;

/// The free elastic disk (tests/disks.hpp) under the single-phase scheme with `transfer`.
std::string disk(const std::string& shape, const std::string& transfer) {
  return loam_test::disk_yaml(shape, "type: single_phase, " + transfer);
}

/// Angular momentum about the centre, with APIC's affine part: the particle's share of the grid's
/// sum_I x_I x (m v)_I is m_p [x_p x v_p + (B_yx - B_xy)] (Jiang et al. 2015), and the kinetic
/// energy sum m v^2 / 2. With linear tents the field holds C_p and B_p = C_p D_p, where the
/// tents' inertia is diagonal, D_dd = xi_d (h - xi_d) for the offset xi_d in the cell.
std::pair<double, double> angular_momentum(loam::Simulation<2>& sim, bool linear) {
  auto& P = sim.sets[0].particles;
  const int B = P.find("affine_moment");
  const double h = sim.grid.cell[0];
  double L = 0, K = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    const double m = P.col(P.mass)[i], x = P.col(P.position, 0)[i] - kCentre,
                 y = P.col(P.position, 1)[i] - kCentre, vx = P.col(P.velocity, 0)[i],
                 vy = P.col(P.velocity, 1)[i];
    L += m * (x * vy - y * vx);
    K += 0.5 * m * (vx * vx + vy * vy);
    if (B < 0) continue;
    double Dxx = 1, Dyy = 1;
    if (linear) {
      const double xi = std::fmod(P.col(P.position, 0)[i], h),
                   eta = std::fmod(P.col(P.position, 1)[i], h);
      Dxx = xi * (h - xi);
      Dyy = eta * (h - eta);
    }
    L += m * (P.col(B, 2)[i] * Dxx - P.col(B, 1)[i] * Dyy);  // B_yx - B_xy
  }
  return {L, K};
}

struct Spin {
  double drift = 0;   // |L_end - L_1| / |L_1|
  double energy = 0;  // K_end / K_1
  double revolutions = 0;
};

/// Spin the disk at kOmega, one step to set the particles' affine matrices, then `steps` more.
Spin spin(const std::string& shape, const std::string& transfer, int steps) {
  auto sim = loam_test::make_simulation<2>(disk(shape, transfer));
  loam_test::set_rigid_rotation(*sim, kOmega, kCentre, kCentre);
  const bool linear = shape == "linear";
  loam_test::advance(*sim, 1);
  const auto [L1, K1] = angular_momentum(*sim, linear);
  const double t1 = sim->time;
  loam_test::advance(*sim, steps);
  const auto [L, K] = angular_momentum(*sim, linear);
  return {std::fabs(L / L1 - 1), K / K1, (sim->time - t1) * kOmega / (2 * M_PI)};
}

}  // namespace

TEST_CASE("apic: a spinning elastic disk keeps its angular momentum to round-off, PIC loses it",
          "[apic][transfer]") {
  // Jiang et al. (2015): APIC's transfers conserve angular momentum exactly (the particle's
  // share including m_p (B_yx - B_xy)), the explicit grid update too for a symmetric stress:
  // the drift over 2000 steps is round-off (target 1e-10). PIC (flip: 0)
  // averages the rotation away at every transfer (measured below).
  for (const char* shape : {"gimp", "bspline2", "cpdi"}) {
    const auto apic = spin(shape, "transfer: apic", 2000);
    const auto pic = spin(shape, "flip: 0", 2000);
    std::printf(
        "spinning disk, %s, %.2f revolutions: APIC angular momentum drift %.2e, kinetic "
        "energy kept %.6f; PIC drift %.2e, kinetic energy kept %.4f\n",
        shape, apic.revolutions, apic.drift, apic.energy, pic.drift, pic.energy);
    CHECK(apic.drift < 1e-10);
    CHECK(pic.drift > 1e-3);
  }
}

TEST_CASE("apic with update usl and usf: the spinning disk keeps its angular momentum",
          "[apic][transfer]") {
  // The same transfers around the other stress updates: USL takes the stress from the updated
  // grid velocities, USF from those of the P2G; neither the transfers nor the grid update change
  // the angular momentum (target 1e-10 over 2000 steps, as MUSL).
  for (const char* update : {"usl", "usf"})
    for (const char* shape : {"gimp", "bspline2"}) {
      const auto apic = spin(shape, std::string("transfer: apic, update: ") + update, 2000);
      std::printf(
          "spinning disk, %s, update %s, %.2f revolutions: APIC angular momentum drift %.2e, "
          "kinetic energy kept %.6f\n",
          shape, update, apic.revolutions, apic.drift, apic.energy);
      CHECK(apic.drift < 1e-10);
      CHECK(std::fabs(apic.energy - 1) < 0.01);
    }
}

TEST_CASE("apic with linear tents (usf): the spinning disk keeps spinning", "[apic][transfer]") {
  // Linear tents carry C_p, the velocity gradient of USF's P2G field at the particle
  // (framework/affine_transfer.hpp says why, and why not with musl or usl): the angular momentum is
  // kept only approximately. Measured and printed; asserted: the disk keeps spinning (kinetic
  // energy and angular momentum within 5 % after 2000 steps), where PIC loses them.
  const auto apic = spin("linear", "transfer: apic, update: usf", 2000);
  const auto pic = spin("linear", "flip: 0, update: usf", 2000);
  std::printf(
      "spinning disk, linear, update usf, %.2f revolutions: APIC angular momentum drift %.2e, "
      "kinetic energy kept %.6f; PIC drift %.2e, kinetic energy kept %.4f\n",
      apic.revolutions, apic.drift, apic.energy, pic.drift, pic.energy);
  CHECK(apic.drift < 0.05);
  CHECK(std::fabs(apic.energy - 1) < 0.05);
  CHECK(pic.drift > 0.5);
}

TEST_CASE("apic: a rigid rotation is kept for 10 revolutions", "[apic][transfer]") {
  // The disk spins 10 times (centrifugal strain rho omega^2 r^2 / E = 2.5e-4: the rigid rotation
  // to that order). APIC: the angular momentum stays to round-off (target 1e-9 over 48 000
  // steps) and the particles keep most of their kinetic energy (measured 2026-12-04: 93 % after
  // 9.3 revolutions; the particle velocities do not carry the affine part's share, m_p tr(C D
  // C^T)/2, nor the elastic exchange, so the target is 90 %). PIC (flip: 0) keeps none.
  const int steps = 48000;
  const auto apic = spin("gimp", "transfer: apic", steps);
  const auto pic = spin("gimp", "flip: 0", steps);
  std::printf(
      "rigid rotation, gimp: %.2f revolutions: APIC kinetic energy kept %.6f, angular "
      "momentum drift %.2e; PIC kinetic energy kept %.4f\n",
      apic.revolutions, apic.energy, apic.drift, pic.energy);
  CHECK(apic.revolutions > 10);
  CHECK(apic.drift < 1e-9);
  CHECK(apic.energy > 0.9);
  CHECK(pic.energy < 0.01);
}

TEST_CASE("apic: bad transfer input gives located errors", "[apic][transfer][bad_config]") {
  loam_test::TempDir dir("apic_bad");
  struct Case {
    std::string scheme, message;
  };
  const Case cases[] = {
      {"{type: single_phase, transfer: polypic}", "scheme.transfer: unknown value 'polypic'"},
      // Linear tents (the default) take APIC with update: usf only (affine_transfer.hpp).
      {"{type: single_phase, transfer: apic}",
       "scheme.transfer: transfer: apic with linear tents needs update: usf"},
      {"{type: single_phase, transfer: apic, update: usl}",
       "scheme.transfer: transfer: apic with linear tents needs update: usf"},
      {"{type: single_phase, transfer: apic, flip: 0.98}",
       "scheme.flip: flip blends FLIP and PIC; transfer: apic replaces both"},
  };
  for (const auto& c : cases)
    loam_test::check_located_error(
        dir.path,
        "grid: {extent: [1, 1], cell_size: 0.25}\nscheme: " + c.scheme +
            "\nbodies:\n  - name: b\n    generator: {type: box, min: [0, 0], max: [0.5, 0.5]}\n"
            "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}\n"
            "time: {end: 0.1}\n",
        "run.yaml:2:", c.message);
}

TEST_CASE(
    "apic and tpic: the vibrating bar's energy drift is at least 5x smaller than with flip 0.98",
    "[apic][tpic][transfer]") {
  // configs/vibrating_bar.yaml (docs/verification.md A: 10 periods of the first mode, 1D), its
  // reference's energy_drift (largest |E - E0| / E0 of the particles' kinetic plus strain energy)
  // with transfer: apic and tpic against the FLIP/PIC blend flip: 0.98 that granular scenes use,
  // for gimp and bspline2 (target: at least 5x smaller, docs/verification.md U). Measured: APIC
  // gimp 0.64 % against 14.0 %, bspline2 1.01 % against 18.0 % (pure FLIP: 0.51 % with gimp); TPIC
  // 0.70 % and 1.13 %. Linear tents take the affine transfers with update: usf (the scheme's
  // header), where TPIC is APIC, so both runs use it there and only APIC runs.
  for (const char* shape : {"gimp", "bspline2", "linear"}) {
    const bool linear = std::string(shape) == "linear";
    const std::string base = std::string("--threads 1 --set shape_function=") + shape +
                             (linear ? " --set scheme.update=usf" : "");
    loam_test::TempDir f("vibrating_bar_flip098");
    const auto sf =
        loam_test::run_scene("vibrating_bar.yaml", f.path, base + " --set scheme.flip=0.98");
    const double df = sf["verify"]["energy_drift"];
    for (const std::string transfer : {"apic", "tpic"}) {
      if (linear && transfer == "tpic") continue;
      loam_test::TempDir a("vibrating_bar_" + transfer);
      const auto sa = loam_test::run_scene("vibrating_bar.yaml", a.path,
                                           base + " --set scheme.transfer=" + transfer);
      const double da = sa["verify"]["energy_drift"];
      std::printf(
          "vibrating bar, %s: energy drift %s %.3f %%, flip 0.98 %.3f %% (%.1fx); period "
          "error %s %.2e, flip 0.98 %.2e\n",
          shape, transfer.c_str(), 100 * da, 100 * df, df / da, transfer.c_str(),
          sa["verify"]["period_error"].get<double>(), sf["verify"]["period_error"].get<double>());
      CHECK(5 * da < df);
    }
  }
}

TEST_CASE("apic and tpic: a rigid translation across cells gives no stress, every shape function",
          "[apic][tpic][transfer][invariance]") {
  // A free bar (1D) and a free block (2D) translating at 1 m/s across 10 cells: the velocity
  // field is uniform, so B_p (APIC) and C_p = sum_I v grad N_Ip^T (TPIC; linear tents) stay zero
  // to round-off, the velocity stays 1 m/s and no stress appears, also as the free ends enter
  // new cells (with linear tents B_p D_p^-1 at a new position once blew this up:
  // framework/affine_transfer.hpp; they run with update: usf). Every step is checked, the first
  // included. Targets: |v - 1| < 1e-12 m/s, |sigma| < 1e-6 Pa (E = 1 MPa).
  for (const std::string transfer : {"apic", "tpic"})
    for (const char* shape : {"linear", "gimp", "bspline2", "cpdi"}) {
      for (int dim : {1, 2}) {
        const std::string yaml =
            std::string(dim == 1 ? "grid: {extent: [3], cell_size: 0.1}\ngravity: [0]\n"
                                 : "grid: {extent: [3, 1], cell_size: 0.1}\ngravity: [0, 0]\n") +
            "shape_function: " + shape + "\nscheme: {type: single_phase, transfer: " + transfer +
            (std::string(shape) == "linear" ? ", update: usf" : "") +
            "}\nbodies:\n  - name: bar\n"
            "    generator: {type: box, min: " +
            (dim == 1 ? "[0.5], max: [1.3]}" : "[0.5, 0.3], max: [1.3, 0.7]}") +
            "\n    particles_per_cell: 2\n    velocity: " + (dim == 1 ? "[1]" : "[1, 0]") +
            "\n    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}\n"
            "time: {end: 10, cfl: 0.5}\n";
        double max_dv = 0, max_sig = 0, moved = 0;
        auto check = [&](auto sim) {
          auto& P = sim->sets[0].particles;
          const double x0 = P.col(P.position, 0)[0];
          for (int n = 0; n < 5000 && P.col(P.position, 0)[0] - x0 < 1.0; ++n) {  // ~650 needed
            loam_test::advance(*sim, 1);
            for (size_t i = 0; i < P.size(); ++i) {
              max_dv = std::max(max_dv, std::fabs(P.col(P.velocity, 0)[i] - 1));
              for (int c = 0; c < P.NS; ++c)
                max_sig = std::max(max_sig, std::fabs(P.col(P.stress, c)[i]));
            }
          }
          moved = P.col(P.position, 0)[0] - x0;
        };
        if (dim == 1)
          check(loam_test::make_simulation<1>(yaml));
        else
          check(loam_test::make_simulation<2>(yaml));
        std::printf(
            "rigid translation, %s, %s, %dD, %.2f m: max |v - 1| %.2e m/s, max |sigma| %.2e Pa\n",
            transfer.c_str(), shape, dim, moved, max_dv, max_sig);
        CHECK(moved >= 1.0);
        CHECK(max_dv < 1e-12);
        CHECK(max_sig < 1e-6);
      }
    }
}

TEST_CASE("apic: a stage's velocity reset zeroes the affine matrices, in every scheme",
          "[apic][transfer][stages]") {
  // A stage's reset: [velocity] must leave no motion behind: the affine matrices are part of
  // the particle velocity field (Scheme::velocity_fields), else the first P2G after the reset
  // sends m_p N B_p D_p^-1 (x_I - x_p) to the nodes. A disk spins for 50 steps (B_p nonzero),
  // then the second stage begins: every velocity and affine component must be exactly 0.
  const std::string tail =
      "stages:\n  - {name: spin, until: static, max_time: 1}\n"
      "  - {name: still, until: static, max_time: 1, reset: [velocity]}\n";
  const std::string sp = disk("gimp", "transfer: apic") + tail;
  const std::string water =
      "material: {type: newtonian_fluid, bulk_modulus: 2.0e7, viscosity: 1.0e-3, density: 1000}";
  const char* names[] = {"single_phase", "two_phase_single_point", "two_phase_double_point"};
  int scheme = 0;
  for (const std::string& yaml :
       {sp,
        "grid: {extent: [2, 2], cell_size: 0.1}\ngravity: [0, 0]\nshape_function: gimp\n"
        "scheme: {type: two_phase_single_point, porosity: 0.4, transfer: apic, drag: {type: "
        "darcy, hydraulic_conductivity: 1.0e-3}}\nbodies:\n  - {name: d, generator: {type: "
        "sphere, center: [1, 1], radius: 0.5}, material: {type: linear_elastic, E: 1.0e6, nu: "
        "0.3, density: 2650}}\ntime: {end: 100, cfl: 0.5}\n" +
            tail,
        "grid: {extent: [2, 2], cell_size: 0.1}\ngravity: [0, 0]\nshape_function: gimp\n"
        "scheme: {type: two_phase_double_point, porosity: 0.4, transfer: apic, drag: {type: "
        "darcy, hydraulic_conductivity: 1.0e-3}}\nbodies:\n  - {name: g, set: solid, "
        "generator: {type: sphere, center: [1, 1], radius: 0.5}, material: {type: "
        "linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}}\n  - {name: w, set: liquid, "
        "generator: {type: sphere, center: [1, 1], radius: 0.5}, " +
            water + "}\ntime: {end: 100, cfl: 0.5}\n" + tail}) {
    std::string staged = yaml;  // a run with stages takes its time from them
    const std::string end = "time: {end: 100, cfl: 0.5}";
    staged.replace(staged.find(end), end.size(), "time: {cfl: 0.5}");
    auto sim = loam_test::make_simulation<2>(staged);
    loam_test::set_rigid_rotation(*sim, kOmega, kCentre, kCentre);
    loam_test::advance(*sim, 50);
    double before = 0, after = 0;
    auto largest = [&] {
      double m = 0;
      for (auto& set : sim->sets) {
        auto& P = set.particles;
        for (const char* f :
             {"velocity", "water_velocity", "affine_moment", "water_affine_moment"}) {
          const int h = P.find(f);
          if (h < 0) continue;
          for (int c = 0; c < P.info(h).components; ++c)
            for (size_t i = 0; i < P.size(); ++i) m = std::max(m, std::fabs(P.col(h, c)[i]));
        }
      }
      return m;
    };
    before = largest();
    sim->begin_stage(1);
    after = largest();
    std::printf("%s: largest velocity or affine component %.3g before the reset, %.3g after\n",
                names[scheme++], before, after);
    CHECK(before > 0.01);
    CHECK(after == 0.0);
  }
}
