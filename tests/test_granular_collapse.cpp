// The granular-collapse scene (configs/granular_collapse_2d.yaml) and the friction boundary it
// uses. Reference: the empirical scaling of quasi-2D laboratory collapses of Lube et al. (2005)
// (plugins/references/granular_collapse.cpp), at a = H0/L0 = 2: (L_f - L0)/L0 = 2.483, H_f/L0
// = 1.320. An experimental trend, so the full tier (the scene as shipped, cell 0.01 m) holds a 15 %
// band. Resolution study (this scene, --set grid.cell_size=h, 2 particles per cell per axis;
// deterministic: 1 and 2 threads give identical results):
//   h (m)     0.04    0.03    0.025   0.02    0.015   0.01    0.0075  0.005
//   run-out   -31.2%  -24.9%  -18.4%  -12.2%  -3.7%   +6.1%   +12.1%  +21.6%  against Lube 2005
//   height    +7.9%   +2.3%   -0.2%   -1.2%   -2.5%   -3.6%   -5.8%   -6.9%
// The run-out is NOT mesh-converged: it grows steadily with refinement (+0.46 L0 from 0.02 to
// 0.01 m, +0.38 L0 from 0.01 to 0.005 m) and passes the Lube value between 0.015 and 0.01 m,
// so the shipped scene's agreement (+6 %) is a property of that cell size; at 0.005 m the full
// tier's 15 % band would fail. It also depends on the time step (cell 0.02: cfl 0.4 / 0.45 / 0.5 /
// 0.55 give -17.7 / -14.9 / -12.2 / -10.0 %), consistent with the 2 % PIC blend (flip 0.98) being
// applied per step, so its dissipation scales with the number of steps. The quick tier runs cell
// 0.02 m (800 particles, ~9000 steps, a few seconds) at the tolerance that resolution achieves.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <vector>

#include "cli.hpp"
#include "framework/simulation.hpp"
#include "sim_helpers.hpp"

namespace {

nlohmann::json collapse(const std::string& name, const std::string& extra) {
  loam_test::TempDir dir(name);
  auto s = loam_test::run_scene("granular_collapse_2d.yaml", dir.path,
                                "--set output.every_time=1.0 " + extra);
  auto v = s["verify"];
  const double runout = v["runout_ratio"], height = v["height_ratio"];
  const double lube_r = v["lube2005_runout_ratio"], lube_h = v["lube2005_height_ratio"];
  std::printf(
      "granular collapse (a = %.2f, %s): run-out (Lf-L0)/L0 = %.3f (Lube 2005: %.3f, %+.1f %%), "
      "Hf/L0 = %.3f (Lube 2005: %.3f, %+.1f %%), final max speed %.3g m/s, %s\n",
      v["aspect_ratio"].get<double>(), extra.c_str(), runout, lube_r, 100 * (runout / lube_r - 1),
      height, lube_h, 100 * (height / lube_h - 1), v["max_speed_final"].get<double>(),
      s["status"].get<std::string>().c_str());
  return s;
}

}  // namespace

TEST_CASE("granular collapse 2D: at cell 0.02 m the deposit is Lube et al. (2005) to 15 % / 3 %",
          "[verification][scene]") {
  // Reference: Lube et al. (2005), run-out and final height (header). At h = 0.02 m the method
  // gives run-out -12.2 % and height -1.2 % (resolution study in the header). Tolerances: 15 %
  // on the run-out (the under-resolved thin front; margin 2.8 points, what a 5 % change of the
  // time step moves it) and 3 % on the height (margin 1.8 points, the height's change for
  // +-10 % in the time step). At rest: final max speed below 0.1 m/s (free fall from H0 would
  // be sqrt(2 g H0) = 2.8 m/s; measured 0.006 m/s).
  // One thread: the result is the same with 1 and 2 (deterministic), and on a loaded machine
  // two OpenMP threads of this small run (800 particles) were measured 20-40x slower.
  auto s = collapse("granular_collapse", "--threads 1 --set grid.cell_size=0.02");
  auto v = s["verify"];
  CHECK(s["status"] == "ok");  // no NaN, no particle left the grid (else exit code 3)
  CHECK(v["max_speed_final"].get<double>() < 0.1);
  CHECK(std::fabs(v["runout_ratio"].get<double>() / v["lube2005_runout_ratio"].get<double>() - 1) <
        0.15);
  CHECK(std::fabs(v["height_ratio"].get<double>() / v["lube2005_height_ratio"].get<double>() - 1) <
        0.03);
}

TEST_CASE("granular collapse 2D: deposit within 15 % of Lube et al. (2005)",
          "[verification][scene][full]") {
  // Reference: Lube et al. (2005). Measured at the shipped 0.01 m: run-out +6.1 %, height
  // -3.6 %. The 15 % band is the experimental trend's scatter, not this resolution's error,
  // and it is NOT a converged result (header: +12.1 % at 0.0075 m, +21.6 % at 0.005 m).
  auto s = collapse("granular_collapse_full", "");
  auto v = s["verify"];
  CHECK(s["status"] == "ok");
  CHECK(v["max_speed_final"].get<double>() < 0.1);
  CHECK(std::fabs(v["runout_ratio"].get<double>() / v["lube2005_runout_ratio"].get<double>() - 1) <
        0.15);
  CHECK(std::fabs(v["height_ratio"].get<double>() / v["lube2005_height_ratio"].get<double>() - 1) <
        0.15);
}

TEST_CASE("friction boundary: a block sliding on the base decelerates at mu g",
          "[boundary][unit]") {
  // Coulomb friction (plugins/boundaries/friction.cpp): an elastic block (one cell high) sliding at
  // v0 on a base with friction mu. References: (1) Coulomb's law in impulse form: while every
  // loaded base node slides, the tangential
  //     impulse is mu times the normal impulse, and the normal impulse over [0, t] is the
  //     weight's, m g t, plus the change of the block's vertical momentum m vy(t) (vy(0) = 0).
  //     Hence, for the mass-weighted mean velocities, exactly
  //         vx(t) = v0 - mu (g t + vy(t)),
  //     checked at every step to 1e-12 m/s (MPM transfers conserve momentum to round-off;
  //     measured 7e-16).
  // (2) The rigid-block deceleration mu g: vx(t) = v0 - mu g t, off by mu vy(t), the block's
  //     vertical vibration about its contact (the uniform initial stress -250 Pa is not the
  //     geostatic gradient: +-125 Pa at the particles, i.e. |vy| <~ 125/(rho c) = 1.3e-3 m/s).
  //     Measured: max |vy| = 4.4e-4 m/s, max over the run of |vx - (v0 - mu g t)| = 1.3e-4
  //     m/s (2e-4 of vx at t = 0.1 s), at t = 0.1 s -1.3e-4 relative. Tolerance 3e-4
  //     relative over the whole run (was 15 % at t = 0.1 s only).
  // And the frictionless case must keep v0 to 1e-9.
  struct Run {
    double vx = 0, t = 0, worst_coulomb = 0, worst_impulse = 0;
  };
  const double g = 10, v0 = 1.0;
  auto run = [&](double mu) {
    const std::string yaml =
        "grid: {extent: [2.0, 0.4], cell_size: 0.05}\n"
        "gravity: [0, -10]\n"
        "scheme: {type: single_phase, update: musl}\n"
        "bodies:\n"
        "  - name: block\n"
        "    generator: {type: box, min: [0.2, 0], max: [0.6, 0.05]}\n"
        "    material: {type: linear_elastic, E: 1.0e7, nu: 0.0, density: 1000}\n"
        "    velocity: [1.0, 0]\n"
        "    stress: [0, -250, 0, 0]\n"
        "boundaries:\n"
        "  - {type: friction, face: y-, coefficient: " +
        std::to_string(mu) + "}\ntime: {end: 1}\n";
    auto sim = loam_test::make_simulation<2>(yaml);
    Run r;
    while (sim->time < 0.1) {
      loam_test::advance(*sim, 1);
      const auto& P = sim->sets[0].particles;
      double mx = 0, my = 0, m = 0;
      for (size_t i = 0; i < P.size(); ++i) {
        mx += P.col(P.mass)[i] * P.col(P.velocity, 0)[i];
        my += P.col(P.mass)[i] * P.col(P.velocity, 1)[i];
        m += P.col(P.mass)[i];
      }
      r.vx = mx / m, r.t = sim->time;
      const double coulomb = v0 - mu * g * r.t;
      r.worst_coulomb = std::max(r.worst_coulomb, std::fabs(r.vx / coulomb - 1));
      r.worst_impulse = std::max(r.worst_impulse, std::fabs(r.vx - (v0 - mu * (g * r.t + my / m))));
    }
    return r;
  };
  const Run free = run(0.0), fric = run(0.3);
  const double expected = v0 - 0.3 * g * fric.t;
  std::printf(
      "friction: mean velocity %.6f m/s at t = %.4f s (Coulomb v0 - mu g t: %.6f, error "
      "%+.2e; worst over the run %.2e); impulse balance v0 - mu (g t + vy): worst %.1e m/s; "
      "frictionless %.10f m/s\n",
      fric.vx, fric.t, expected, fric.vx / expected - 1, fric.worst_coulomb, fric.worst_impulse,
      free.vx);
  CHECK(std::fabs(free.vx - v0) < 1e-9);
  CHECK(fric.worst_impulse < 1e-12);
  CHECK(fric.worst_coulomb < 3e-4);
}

TEST_CASE("granular collapse 2D: an unknown body in verify is a located error naming the bodies",
          "[verification][cli]") {
  loam_test::TempDir dir("granular_collapse_bad");
  auto r = loam_test::run_loam("run " + std::string(LOAM_SOURCE_DIR) +
                               "/configs/granular_collapse_2d.yaml --quiet --out " +
                               dir.path.string() + " --set verify.body=snad");
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(r.output ==
        "<--set verify.body=snad>:1:1: error: verify.body: unknown body 'snad'; "
        "bodies are: sand\n");
  CHECK_FALSE(std::filesystem::exists(dir.path));
}

TEST_CASE(
    "granular collapse 2D with drucker_prager: the plane-strain cone gives Mohr-Coulomb's "
    "deposit, the compression cone a much shorter one",
    "[verification][scene][drucker_prager]") {
  // The scene at cell 0.02 m (as the quick test above) with the same c, phi, psi in the
  // drucker_prager material (docs/verification.md B2). The collapse is plane strain: the cone
  // matched to plane strain carries about Mohr-Coulomb's strength there (exactly so for
  // associated flow; here psi = 0), the compression (outer) cone is stronger off the triaxial
  // compression meridian. Measured 2026-12-04 (run-out ratio (Lf - L0)/L0): Mohr-Coulomb 2.179,
  // plane_strain cone 2.291 (+5 %), extension cone 2.199, compression cone 1.457 (-33 %).
  // Targets: the plane-strain cone's run-out within 10 % of Mohr-Coulomb's; the compression
  // cone's below 0.8 of the plane-strain cone's; every run at rest.
  const std::string cell = "--threads 1 --set grid.cell_size=0.02";
  const std::string dp = " --set bodies.0.material.type=drucker_prager";
  auto mc = collapse("collapse_mc", cell)["verify"];
  auto ps = collapse("collapse_dp_ps", cell + dp + " --set bodies.0.material.match=plane_strain");
  auto co = collapse("collapse_dp_c", cell + dp + " --set bodies.0.material.match=compression");
  for (const auto& s : {ps, co}) {
    CHECK(s["status"] == "ok");
    CHECK(s["verify"]["max_speed_final"].get<double>() < 0.1);
  }
  const double r_mc = mc["runout_ratio"], r_ps = ps["verify"]["runout_ratio"],
               r_c = co["verify"]["runout_ratio"];
  std::printf(
      "granular collapse, run-out ratio: Mohr-Coulomb %.3f, DP plane strain %.3f (%+.1f %% "
      "of MC's), DP compression %.3f (%.2f of the plane-strain cone's)\n",
      r_mc, r_ps, 100 * (r_ps / r_mc - 1), r_c, r_c / r_ps);
  CHECK(std::fabs(r_ps / r_mc - 1) < 0.10);
  CHECK(r_c < 0.8 * r_ps);
}

TEST_CASE("granular collapse 2D with APIC and no PIC blend comes to rest",
          "[verification][scene][apic]") {
  // The collapse with transfer: apic (gimp, MUSL; linear tents take APIC with USF
  // only, framework/affine_transfer.hpp; docs/transfers.md, The granular collapse) and no PIC
  // blend, beside the flip: 0.98 run on the same gimp grid and Lube et al. (2005). The test
  // asserts that it comes to rest (final max speed below 0.1 m/s, as the quick test above) and
  // prints the deposit. Measured 2026-12-04, cell 0.02 m, run-out ratio / height ratio (Lube
  // 2.483 / 1.320): flip 0.98 2.155 / 1.255; APIC Mohr-Coulomb 3.263 / 1.163; APIC
  // drucker_prager (plane_strain cone) 3.381 / 1.142. Cell 0.01 m: 2.627 / 1.232, 4.005 / 1.141,
  // 4.202 / 1.108: without PIC's dissipation the front runs 31-61 % past Lube's value and
  // further on the finer grid (docs/verification.md U).
  const std::string gimp = "--threads 1 --set grid.cell_size=0.02 --set shape_function=gimp";
  const std::string apic = " --set scheme.transfer=apic --set scheme.flip=1";
  auto flip = collapse("collapse_gimp_flip", gimp)["verify"];
  auto mc = collapse("collapse_gimp_apic_mc", gimp + apic);
  auto dp =
      collapse("collapse_gimp_apic_dp", gimp + apic +
                                            " --set bodies.0.material.type=drucker_prager --set "
                                            "bodies.0.material.match=plane_strain");
  for (const auto& s : {mc, dp}) {
    CHECK(s["status"] == "ok");
    CHECK(s["verify"]["max_speed_final"].get<double>() < 0.1);
  }
  std::printf(
      "granular collapse, gimp 0.02 m: run-out ratio flip 0.98 %.3f, APIC MC %.3f, APIC "
      "DP %.3f (Lube 2005: %.3f)\n",
      flip["runout_ratio"].get<double>(), mc["verify"]["runout_ratio"].get<double>(),
      dp["verify"]["runout_ratio"].get<double>(), flip["lube2005_runout_ratio"].get<double>());
}
