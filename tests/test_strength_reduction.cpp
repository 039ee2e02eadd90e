// Strength reduction (docs/strength_reduction.md) and the periodic grid it is tested
// on. The factor of safety of an infinite cohesionless slope with associated flow is
// tan(phi) / tan(beta) (docs/strength_reduction.md, Infinite slope); trials restart from the same
// static state (a trial's record does not depend on the trials before it); a periodic grid keeps
// a rigid translation across its faces stress-free; bad input gives located errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <utility>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;

/// summary.json of a run directory.
nlohmann::json summary_of(const fs::path& out) {
  std::ifstream in(out / "summary.json");
  return nlohmann::json::parse(in);
}

/// The trial of factor F in a strength_reduction record (null if none).
nlohmann::json trial_at(const nlohmann::json& srf, double F) {
  for (const auto& t : srf["trials"])
    if (t["factor"].get<double>() == F) return t;
  return nullptr;
}

/// A small 2D model for the bad-input cases: one Mohr-Coulomb body `soil`, one elastic body
/// `rock`, then `rest` (from line 11 on), with a shape function.
std::string model(const std::string& rest, const std::string& shape = "linear") {
  return "grid: {extent: [1.0, 1.2], cell_size: 0.1}\n"
         "shape_function: " +
         shape + "\n" +
         "gravity: [0, -9.81]\n"
         "bodies:\n"
         "  - name: soil\n"
         "    generator: {type: box, min: [0, 0.5], max: [1, 1]}\n"
         "    material: {type: mohr_coulomb, E: 1.0e7, nu: 0.3, density: 2000, c: 0, phi: 30, psi: "
         "0}\n"
         "  - name: rock\n"
         "    generator: {type: box, min: [0, 0], max: [1, 0.5]}\n"
         "    material: {type: linear_elastic, E: 1.0e8, nu: 0.3, density: 2500}\n" +
         rest;
}

/// configs/infinite_slope_srf.yaml (psi = phi) with scheme.volumetric `volumetric` and `search`
/// (--set's of strength_reduction): the factor within 5 % of tan(phi) / tan(beta), a consistent
/// bisection, and the mechanism frame written.
void check_infinite_slope(const std::string& volumetric, const std::string& search = "") {
  loam_test::TempDir d("srf_infinite");
  const auto s =
      loam_test::run_scene("infinite_slope_srf.yaml", d.path / "out",
                           "--threads 2 --set scheme.volumetric=" + volumetric + " " + search);
  const auto& srf = s["strength_reduction"];
  INFO(srf.dump(1));
  REQUIRE(srf["status"] == "converged");
  // The slope angle from the config's tilted gravity, phi from its material.
  const auto& g = s["config"]["gravity"];
  const double beta = std::atan(g[0].get<double>() / -g[1].get<double>());
  const double phi = s["config"]["bodies"][0]["material"]["phi"].get<double>() * M_PI / 180;
  const double exact = std::tan(phi) / std::tan(beta);
  const double fos = s["factor_of_safety"].get<double>();
  const double lo = s["factor_of_safety_bracket"][0], hi = s["factor_of_safety_bracket"][1];
  std::printf(
      "infinite slope, volumetric %s, beta = %.4f deg, phi = 30 deg, c = 0, psi = phi: FoS = "
      "%.4f (bracket [%.4f, %.4f], %zu trials, %.1f s wall) against tan(phi)/tan(beta) = %.4f: "
      "%+.2f %% (tolerance 5 %%)\n",
      volumetric.c_str(), beta * 180 / M_PI, fos, lo, hi, srf["trials"].size(),
      srf["wall_seconds"].get<double>(), exact, 100 * (fos / exact - 1));
  CHECK(std::abs(fos / exact - 1) < 0.05);
  CHECK(hi - lo <= srf["tolerance"].get<double>() * (1 + 1e-9));
  CHECK(fos == Approx(0.5 * (lo + hi)));
  // The bisection is consistent: every factor up to lo was stable, every one from hi failed.
  for (const auto& t : srf["trials"]) {
    const double F = t["factor"];
    if (F <= lo) CHECK(t["status"] == "static");
    if (F >= hi) CHECK(t["status"] != "static");
  }
  // The stages before it ended static, and the mechanism frame of the lowest failed factor was
  // written with its plastic strain.
  for (const auto& st : s["stages"]) CHECK(st["status"] == "static");
  fs::path mechanism;
  for (const auto& e : fs::directory_iterator(d.path / "out"))
    if (e.path().filename().string().find("_strength_reduction.h5") != std::string::npos)
      mechanism = e.path();
  REQUIRE(!mechanism.empty());
  const auto eq = loam_test::read_frame_doubles(mechanism, "plastic_strain_eq");
  double eq_max = 0;
  for (double v : eq) eq_max = std::max(eq_max, v);
  std::printf("mechanism frame %s: largest plastic strain %.3g\n", mechanism.filename().c_str(),
              eq_max);
  CHECK(eq_max > 1e-3);
}

}  // namespace

TEST_CASE("strength reduction of an infinite cohesionless slope gives tan(phi) / tan(beta)",
          "[srf]") {
  // A short search, [1.5, 1.7] to 0.06 (trials 1.5, 1.7, 1.6, 1.55): the config's own, whose
  // F = 1.5875 trial creeps for 40 s, runs in the [full] test of the verdict's invariance.
  check_infinite_slope("none",
                       "--set strength_reduction.factors=[1.5,1.7] --set "
                       "strength_reduction.tolerance=0.06");
}

TEST_CASE("strength reduction with F-bar: the infinite slope still gives tan(phi) / tan(beta)",
          "[srf][locking][full]") {
  // F-bar's consistent-mass projection (framework/fbar.hpp) keeps dilatant flow at the
  // strength the material has (with a lumped nodal average and the particles' own mean stress
  // in the force the factor was 1.331: the layer heaved and blew up).
  check_infinite_slope("fbar");
}

TEST_CASE(
    "a strength-reduction verdict depends neither on the thread count nor on max_time (psi = 0 "
    "and psi = phi)",
    "[srf][full]") {
  // docs/strength_reduction.md, "What a trial does" and "A verdict near the factor": the motion
  // decides a trial (at rest: stable; failure_displacement reached: failed), max_time only
  // bounds it. The infinite slope with psi = 0 creeps for up to 22 s before it stops near the
  // factor; with psi = phi, F = 1.5875 creeps on at about 0.6 mm/s. With the config's max_time
  // (60 s) every trial decides, so the search must be `converged` with the same bracket at 1
  // and 2 threads and with max_time doubled; for psi = phi the bracket must hold tan(phi) /
  // tan(beta) = 1.5863. Printed: the factor and bracket of each run.
  for (const std::string psi : {"0", "30"}) {
    const std::string psi_set =
        " --set bodies.0.material.psi=" + psi + " --set stages.1.materials.0.material.psi=" + psi;
    const std::pair<int, double> runs[] = {{1, 60}, {2, 60}, {1, 120}};
    nlohmann::json srf[3];
    for (int k = 0; k < 3; ++k) {
      loam_test::TempDir d("srf_invariance");
      const auto [threads, max_time] = runs[k];
      const auto s = loam_test::run_scene(
          "infinite_slope_srf.yaml", d.path / "out",
          "--threads " + std::to_string(threads) +
              " --set strength_reduction.max_time=" + std::to_string(max_time) + psi_set);
      srf[k] = s["strength_reduction"];
      std::printf(
          "infinite slope, psi = %s deg, %d thread(s), max_time %g s: %s, FoS %.4f, bracket "
          "[%.4f, %.4f], %zu trials, %.1f s wall\n",
          psi.c_str(), threads, max_time, srf[k]["status"].get<std::string>().c_str(),
          s["factor_of_safety"].get<double>(), s["factor_of_safety_bracket"][0].get<double>(),
          s["factor_of_safety_bracket"][1].get<double>(), srf[k]["trials"].size(),
          srf[k]["wall_seconds"].get<double>());
      INFO(srf[k].dump(1));
      CHECK(srf[k]["status"] == "converged");
      if (k > 0) CHECK(s["factor_of_safety_bracket"] == srf[0]["factor_of_safety_bracket"]);
      if (psi == "30") {
        const double exact = std::tan(M_PI / 6) / std::tan(20 * M_PI / 180);
        CHECK(s["factor_of_safety_bracket"][0].get<double>() <= exact);
        CHECK(s["factor_of_safety_bracket"][1].get<double>() >= exact);
      }
    }
    // Threads: the same bits, so every trial's record is equal.
    REQUIRE(srf[0]["trials"].size() == srf[1]["trials"].size());
    for (size_t i = 0; i < srf[0]["trials"].size(); ++i) {
      const auto &a = srf[0]["trials"][i], &b = srf[1]["trials"][i];
      CHECK(a["factor"] == b["factor"]);
      CHECK(a["status"] == b["status"]);
      CHECK(a["steps"] == b["steps"]);
      CHECK(a["max_displacement"].get<double>() == b["max_displacement"].get<double>());
    }
  }
}

TEST_CASE(
    "a trial still moving at max_time is undecided, and the search says so when it bounds "
    "the bracket",
    "[srf]") {
  // docs/strength_reduction.md, "What a trial does": with psi = phi, F = 1.5875 creeps at about
  // 0.6 mm/s and has moved about 0.02 m of the 0.05 m failure_displacement after 2 s. With
  // max_time 2 s (searching [1.55, 1.6]: 1.575 comes to rest in 0.9 s) it bounds the bracket
  // undecided: status `undecided`, undecided_factor 1.5875, a warning.
  loam_test::TempDir d("srf_undecided");
  const auto r = loam_test::run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                                     "/configs/infinite_slope_srf.yaml" + " --out " +
                                     (d.path / "out").string() +
                                     " --threads 2 --set strength_reduction.max_time=2 --set "
                                     "strength_reduction.factors=[1.55,1.6]");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto s = summary_of(d.path / "out");
  const auto& srf = s["strength_reduction"];
  INFO(srf.dump(1));
  CHECK(srf["status"] == "undecided");
  CHECK(srf["undecided_factor"].get<double>() == s["factor_of_safety_bracket"][1].get<double>());
  CHECK(trial_at(srf, srf["undecided_factor"].get<double>())["status"] == "undecided");
  CHECK(r.output.find("was still moving when max_time = 2 s passed") != std::string::npos);
  std::printf(
      "max_time 2 s: %s, bracket [%.4f, %.4f], undecided F = %.4f\n",
      srf["status"].get<std::string>().c_str(), s["factor_of_safety_bracket"][0].get<double>(),
      s["factor_of_safety_bracket"][1].get<double>(), srf["undecided_factor"].get<double>());
}

TEST_CASE("strength-reduction trials restart from the same static state", "[srf]") {
  // F = 1.6 is the third trial of both searches, after (1.2, 2.0) in one and (1.4, 1.8) in the
  // other: its record must be the same to the bit (trials of at most 2 s: F = 1.6 is then
  // undecided in both).
  loam_test::TempDir a("srf_order_a"), b("srf_order_b");
  const std::string common =
      "--threads 1 --set strength_reduction.tolerance=0.3 --set strength_reduction.max_time=2";
  const auto sa = loam_test::run_scene("infinite_slope_srf.yaml", a.path / "out", common);
  const auto sb = loam_test::run_scene("infinite_slope_srf.yaml", b.path / "out",
                                       common + " --set strength_reduction.factors=[1.4,1.8]");
  const auto ta = trial_at(sa["strength_reduction"], 1.6),
             tb = trial_at(sb["strength_reduction"], 1.6);
  INFO(sa["strength_reduction"].dump(1) << sb["strength_reduction"].dump(1));
  REQUIRE(!ta.is_null());
  REQUIRE(!tb.is_null());
  std::printf(
      "F = 1.6 after (1.2, 2.0) and after (1.4, 1.8): %s / %s, %ld / %ld steps, largest "
      "displacement %.17g / %.17g m\n",
      ta["status"].get<std::string>().c_str(), tb["status"].get<std::string>().c_str(),
      ta["steps"].get<long>(), tb["steps"].get<long>(), ta["max_displacement"].get<double>(),
      tb["max_displacement"].get<double>());
  CHECK(ta["status"] == tb["status"]);
  CHECK(ta["steps"] == tb["steps"]);
  CHECK(ta["max_displacement"].get<double>() == tb["max_displacement"].get<double>());
  CHECK(ta["motion_speed"].get<double>() == tb["motion_speed"].get<double>());
  // After the search the model is back in its static state: both runs end identical.
  CHECK(sa["energy_final"] == sb["energy_final"]);
}

TEST_CASE("a periodic grid carries a rigid translation across its faces without stress",
          "[srf][periodic][invariance]") {
  // A 1 m x 0.5 m block filling the periodic width moves at (2, 0.5) m/s for 1 s, no gravity:
  // every particle crosses the periodic faces twice. Reference: a rigid translation gives no
  // strain, so the stress stays at round-off, and x = x0 + 2 t (mod 1), y = y0 + 0.5 t.
  loam_test::TempDir d("periodic_rigid");
  const std::string yaml =
      "grid: {extent: [1.0, 1.5], cell_size: 0.1}\n"
      "shape_function: linear\n"
      "bodies:\n"
      "  - name: block\n"
      "    generator: {type: box, min: [0, 0.2], max: [1, 0.7]}\n"
      "    velocity: [2, 0.5]\n"
      "    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}\n"
      "boundaries:\n"
      "  - {type: periodic, axis: x}\n"
      "time: {end: 1.0}\n"
      "output: {every_time: 1.0, fields: [velocity, stress, displacement]}\n";
  auto r = loam_test::run_yaml(d.path, yaml, "--threads 2");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const fs::path last = d.path / "out" / "particles_000001.h5";
  REQUIRE(fs::exists(last));
  const auto x = loam_test::read_frame_doubles(last, "position");
  const auto u = loam_test::read_frame_doubles(last, "displacement");
  const auto v = loam_test::read_frame_doubles(last, "velocity");
  const auto s = loam_test::read_frame_doubles(last, "stress");
  const size_t n = x.size() / 3;
  REQUIRE(n == 200);
  double s_max = 0, v_err = 0, x_err = 0;
  for (double c : s) s_max = std::max(s_max, std::abs(c));
  const double t = summary_of(d.path / "out")["end_time"];
  for (size_t i = 0; i < n; ++i) {
    v_err = std::max({v_err, std::abs(v[3 * i] - 2), std::abs(v[3 * i + 1] - 0.5)});
    double dx = u[3 * i] - 2 * t;  // the displacement output jumps by the period on a wrap
    dx -= std::round(dx);
    x_err = std::max({x_err, std::abs(dx), std::abs(u[3 * i + 1] - 0.5 * t)});
    CHECK(x[3 * i] >= 0.0);
    CHECK(x[3 * i] < 1.0);
  }
  std::printf(
      "periodic rigid translation, 1 s at (2, 0.5) m/s: largest |stress| %.3g Pa "
      "(tolerance 1e-5), velocity error %.3g m/s, position error %.3g m (1e-9)\n",
      s_max, v_err, x_err);
  CHECK(s_max < 1e-5);
  CHECK(v_err < 1e-9);
  CHECK(x_err < 1e-9);
}

TEST_CASE("bad strength-reduction and periodic input: located errors, exit 2, no output",
          "[srf][bad_config]") {
  loam_test::TempDir d("srf_bad");
  const std::string stages =
      "stages:\n"
      "  - {name: gravity, until: static, max_time: 1}\n";  // line 13
  auto check = [&](const std::string& yaml, const std::vector<std::string>& lines) {
    auto r = loam_test::run_yaml(d.path, yaml);
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK_FALSE(fs::exists(d.path / "out"));
    const std::string f = (d.path / "run.yaml").string();
    for (const auto& e : lines) {
      INFO(e);
      CHECK(r.output.find(f + e) != std::string::npos);
    }
  };
  // The schema: F_high below F_low, missing max_time and failure_displacement, the last stage
  // not until: static.
  check(model("boundaries: [{type: fixed, face: y-}]\n"
              "stages:\n"
              "  - {name: gravity, until: static, max_time: 1}\n"
              "  - {name: more, duration: 1}\n"
              "strength_reduction: {factors: [2.0, 1.5]}\n"),  // line 15
        {":15:21: error: strength_reduction: strength reduction starts from a static state",
         ":15:31: error: strength_reduction.factors: factors = [2, 1.5]: F_high must exceed "
         "F_low",
         ":15:21: error: strength_reduction.max_time: missing required key 'max_time'",
         ":15:21: error: strength_reduction.failure_displacement: missing required key "
         "'failure_displacement'"});
  // The bodies: an unknown one, an elastic one.
  check(model("boundaries: [{type: fixed, face: y-}]\n" + stages +
              "strength_reduction: {factors: [1, 2], max_time: 1, failure_displacement: 0.1, "
              "bodies: [sand, rock]}\n"),
        {":14:88: error: strength_reduction.bodies.0: unknown body 'sand'; bodies are: soil, rock",
         ":14:94: error: strength_reduction.bodies.1: body 'rock' has a material without a "
         "strength to reduce"});
  // Periodic with a wide stencil, and with a face another condition holds.
  check(model("boundaries: [{type: fixed, face: y-}, {type: periodic, axis: x}, {type: slip, "
              "face: x+}]\n" +
                  stages,
              "gimp"),
        {":11:39: error: boundaries.1: a periodic grid needs a stencil of two nodes per axis",
         ":11:39: error: boundaries.1: another condition (boundaries.2) holds face x+"});
}

TEST_CASE("the seed-004 slope's factor of safety by strength reduction, beside Bishop's",
          "[srf][seed004][full]") {
  // docs/strength_reduction.md, The seed-004 slope against Bishop. Bishop's simplified method
  // (tools/bishop.py) for the same slope: 2.089. Measured 2026-12-03: 2.324 (bracket [2.319,
  // 2.330]), +11.3 %. The guard [2.24, 2.42] is a regression band of 4 % around the measured
  // value (the SRF factor of a coarse model is expected above the limit-equilibrium one), not a
  // tolerance against Bishop.
  loam_test::TempDir d("srf_seed004");
  const auto s = loam_test::run_scene("seed004_slope_srf.yaml", d.path / "out", "--threads 2");
  const auto& srf = s["strength_reduction"];
  INFO(srf.dump(1));
  REQUIRE(srf["status"] == "converged");
  auto b = loam_test::run_command("/usr/bin/python3 " + std::string(LOAM_SOURCE_DIR) +
                                  "/tools/bishop.py --json --height 4.5 --angle 26.565 "
                                  "--gamma 15696 --c 5000 --phi 30 --depth 5");
  REQUIRE(b.exit_code == 0);
  const double bishop = nlohmann::json::parse(b.output)["factor_of_safety"];
  const double fos = s["factor_of_safety"];
  std::printf(
      "seed-004 slope: SRF FoS = %.4f (bracket [%.4f, %.4f], %zu trials, %ld trial steps, %.0f "
      "s wall) against Bishop %.4f: %+.1f %% (regression band 2.24-2.42)\n",
      fos, s["factor_of_safety_bracket"][0].get<double>(),
      s["factor_of_safety_bracket"][1].get<double>(), srf["trials"].size(),
      srf["steps"].get<long>(), s["wall_seconds"].get<double>(), bishop, 100 * (fos / bishop - 1));
  CHECK(fos > 2.24);
  CHECK(fos < 2.42);
  CHECK(fos > bishop);  // a coarse SRF model is not more critical than limit equilibrium
  // The verdict is the motion's, not patience's or the threads': on 1 thread with max_time
  // doubled (40 s) the search ends in the same bracket.
  {
    loam_test::TempDir d2("srf_seed004_long");
    const auto s2 = loam_test::run_scene("seed004_slope_srf.yaml", d2.path / "out",
                                         "--threads 1 --set strength_reduction.max_time=40");
    std::printf("seed-004 slope, 1 thread, max_time 40 s: %s, bracket [%.4f, %.4f]\n",
                s2["strength_reduction"]["status"].get<std::string>().c_str(),
                s2["factor_of_safety_bracket"][0].get<double>(),
                s2["factor_of_safety_bracket"][1].get<double>());
    CHECK(s2["strength_reduction"]["status"] == "converged");
    CHECK(s2["factor_of_safety_bracket"] == s["factor_of_safety_bracket"]);
  }
  // The mechanism: the particle that moved most in the lowest failed trial is on the slope's
  // face or crest edge (x in [6, 17] m, above the base layer), a slide, not the base.
  fs::path mechanism;
  for (const auto& e : fs::directory_iterator(d.path / "out"))
    if (e.path().filename().string().find("_strength_reduction.h5") != std::string::npos)
      mechanism = e.path();
  REQUIRE(!mechanism.empty());
  const auto x = loam_test::read_frame_doubles(mechanism, "position");
  const auto u = loam_test::read_frame_doubles(mechanism, "displacement");
  size_t k = 0;
  double u_max = 0;
  for (size_t i = 0; i < x.size() / 3; ++i) {
    const double a = std::hypot(u[3 * i], u[3 * i + 1]);
    if (a > u_max) u_max = a, k = i;
  }
  std::printf("largest displacement %.3f m at (%.2f, %.2f) m\n", u_max, x[3 * k], x[3 * k + 1]);
  CHECK(x[3 * k] > 6);
  CHECK(x[3 * k] < 17);
  CHECK(x[3 * k + 1] > 5);
}

TEST_CASE(
    "with F-bar the seed-004 factor of safety is within 6 % (0.5 m) and 3 % (0.25 m) of "
    "Bishop's",
    "[srf][seed004][locking][full]") {
  // docs/strength_reduction.md, The seed-004 slope against Bishop; docs/volumetric_locking.md.
  // psi = 0 flow locks: without a treatment the factor is +11.3 % (0.5 m cells) and +4.5 %
  // (0.25 m) above Bishop's 2.089 (tools/bishop.py). With F-bar the targets are within 6 % on
  // 0.5 m cells and 3 % on 0.25 m cells, from above (a coarse SRF model is not more critical
  // than limit equilibrium). Measured 2026-12-07: 2.193 (+5.0 %) and 2.138 (+2.4 %).
  const double bishop = 2.089;
  for (const auto& [h, tolerance] : {std::pair{0.5, 0.06}, std::pair{0.25, 0.03}}) {
    loam_test::TempDir d("srf_seed004_fbar");
    const auto s = loam_test::run_scene(
        "seed004_slope_srf.yaml", d.path / "out",
        "--threads 2 --set scheme.volumetric=fbar --set grid.cell_size=" + std::to_string(h));
    REQUIRE(s["strength_reduction"]["status"] == "converged");
    const double fos = s["factor_of_safety"];
    std::printf(
        "seed-004 slope with F-bar, %.2f m cells: FoS %.4f (bracket [%.4f, %.4f], %.0f s wall) "
        "against Bishop %.3f: %+.1f %% (tolerance %.0f %%)\n",
        h, fos, s["factor_of_safety_bracket"][0].get<double>(),
        s["factor_of_safety_bracket"][1].get<double>(), s["wall_seconds"].get<double>(), bishop,
        100 * (fos / bishop - 1), 100 * tolerance);
    CHECK(fos > bishop);
    CHECK(fos / bishop - 1 < tolerance);
  }
}
