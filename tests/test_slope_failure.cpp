// The measurements of the slope scenes (docs/slope_scenes.md): the `slope_failure` reference (the
// failed mass, its depth, run-out, deposit top and time to rest;
// plugins/references/slope_failure.cpp) and the `strain_magnitude` output (||eps|| of the
// logarithmic strain since the last reset; framework/strain_measure.hpp), tested on motions whose
// answers are known exactly.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "cli.hpp"
#include "framework/strain_measure.hpp"

namespace {

namespace fs = std::filesystem;

nlohmann::json summary_of(const fs::path& out) {
  std::ifstream in(out / "summary.json");
  return nlohmann::json::parse(in);
}

/// The newest regular frame of a run directory (particles_NNNNNN.h5, no label).
fs::path last_frame(const fs::path& out) {
  fs::path best;
  for (const auto& e : fs::directory_iterator(out)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("particles_", 0) == 0 && n.size() == std::string("particles_000000.h5").size() &&
        (best.empty() || n > best.filename().string()))
      best = e.path();
  }
  return best;
}

/// A block [1, 3] x [1, 2] m of nearly strengthless elastic material (E = 1 Pa: its stress
/// stays below 1 Pa) in a 10 x 4 m grid without gravity, moving with `velocity` (a field), and
/// then `rest`.
std::string block(const std::string& velocity, const std::string& rest) {
  return "grid: {extent: [10, 4], cell_size: 0.5}\n"
         "shape_function: linear\n"
         "scheme: {type: single_phase, update: musl}\n"
         "bodies:\n"
         "  - name: block\n"
         "    generator: {type: box, min: [1, 1], max: [3, 2]}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1, nu: 0.3, density: 1000}\n"
         "    velocity: " +
         velocity + "\n" + rest;
}

}  // namespace

TEST_CASE("hencky_strain_norm: zero for rotations, |ln stretch| for stretches, relative to F_ref",
          "[slope][strain]") {
  const double I2[4] = {1, 0, 0, 1}, I3[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  const double c = std::cos(0.7), s = std::sin(0.7);
  const double R2[4] = {c, -s, s, c};
  CHECK(loam::hencky_strain_norm<2>(R2, I2) < 1e-15);
  const double R3[9] = {c, 0, s, 0, 1, 0, -s, 0, c};
  CHECK(loam::hencky_strain_norm<3>(R3, I3) < 1e-15);
  // A stretch then a rotation (F = R U): the stretch's log, whatever the rotation.
  const double RU[4] = {c * 1.3, -s * 0.8, s * 1.3, c * 0.8};
  CHECK(loam::hencky_strain_norm<2>(RU, I2) ==
        Approx(std::hypot(std::log(1.3), std::log(0.8))).epsilon(1e-14));
  const double U3[9] = {1.1, 0, 0, 0, 0.9, 0, 0, 0, 1.25};
  const double e3 = std::sqrt(std::pow(std::log(1.1), 2) + std::pow(std::log(0.9), 2) +
                              std::pow(std::log(1.25), 2));
  CHECK(loam::hencky_strain_norm<3>(U3, I3) == Approx(e3).epsilon(1e-14));
  const double F1[1] = {0.8}, I1[1] = {1};
  CHECK(loam::hencky_strain_norm<1>(F1, I1) == Approx(-std::log(0.8)).epsilon(1e-14));
  // Relative to a reference state: F = G F_ref measures G only.
  const double Fref[4] = {1.2, 0.3, -0.1, 0.9};
  const double G[4] = {1.3, 0, 0, 0.8};
  double F[4];
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) F[i * 2 + j] = G[i * 2] * Fref[j] + G[i * 2 + 1] * Fref[2 + j];
  CHECK(loam::hencky_strain_norm<2>(F, Fref) ==
        Approx(std::hypot(std::log(1.3), std::log(0.8))).epsilon(1e-13));
  // Small strain: sqrt(eps:eps) of the small-strain tensor (a simple shear gamma: gamma/sqrt 2).
  const double g = 1e-5, S[4] = {1, g, 0, 1};
  CHECK(loam::hencky_strain_norm<2>(S, I2) == Approx(g / std::sqrt(2.0)).epsilon(1e-6));
}

TEST_CASE("strain_magnitude output: the frames' F since the last reset, zero after a reset",
          "[slope][strain]") {
  // v_x = 0.2 (x - 2) stretches the block along x about its centre (E = 1e-9 Pa: no force worth
  // the name). At the end of the stretch (t = 1 s) every particle's strain_magnitude is
  // hencky_strain_norm of its written F (the wiring; F's own integration is tested by the
  // hencky material's exact column, tests/test_large_strain.cpp). Then a stage resets the
  // displacement (the strain's reference too) and the velocity: the block stands, F stays
  // stretched, and the strain since the reset is 0.
  loam_test::TempDir d("strain_magnitude");
  std::string yaml =
      block("{type: linear_profile, value: [0, 0], gradient: [0.2, 0], axis: 0, origin: 2}",
            "time: {dt: 0.01}\n"
            "output: {every_time: 0.5, fields: [strain_magnitude, deformation_gradient]}\n"
            "stages:\n"
            "  - {name: stretch, duration: 1}\n"
            "  - name: stand\n"
            "    duration: 0.5\n"
            "    reset: [displacement, velocity]\n");
  yaml.replace(yaml.find("E: 1,"), 5, "E: 1.0e-9,");
  auto r = loam_test::run_yaml(d.path, yaml);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const fs::path out = d.path / "out";
  const auto x0 = loam_test::read_frame_doubles(out / "particles_000000.h5", "position");
  const auto x1 = loam_test::read_frame_doubles(out / "particles_000002.h5", "position");
  const auto eps = loam_test::read_frame_doubles(out / "particles_000002.h5", "strain_magnitude");
  const auto F = loam_test::read_frame_doubles(out / "particles_000002.h5", "deformation_gradient");
  REQUIRE(eps.size() * 3 == x1.size());
  REQUIRE(eps.size() * 4 == F.size());
  auto length = [](const std::vector<double>& x) {
    double lo = 1e300, hi = -1e300;
    for (size_t i = 0; i < x.size(); i += 3) lo = std::min(lo, x[i]), hi = std::max(hi, x[i]);
    return hi - lo;
  };
  const double I[4] = {1, 0, 0, 1};
  double wiring = 0, mean = 0;
  for (size_t i = 0; i < eps.size(); ++i) {
    wiring = std::max(wiring, std::abs(eps[i] - loam::hencky_strain_norm<2>(&F[4 * i], I)));
    mean += eps[i] / double(eps.size());
  }
  const double stretch = std::log(length(x1) / length(x0));
  // The block's stretch from its end particles, for scale (the grid under-reads the velocity
  // at the block's edges, where its nodes see particles on one side only).
  std::printf(
      "strain_magnitude at the end of the stretch: mean %.6f (the block's ln(L/L0) = "
      "%.6f); against hencky_strain_norm(F) of the frame: %.1e (tolerance 1e-14)\n",
      mean, stretch, wiring);
  CHECK(mean > 0.15);
  CHECK(wiring < 1e-14);
  // After the reset the block stands still: F keeps its stretch, the strain since the reset is 0.
  const fs::path end = last_frame(out);
  const auto eps_end = loam_test::read_frame_doubles(end, "strain_magnitude");
  const auto F_end = loam_test::read_frame_doubles(end, "deformation_gradient");
  double largest = 0, Fxx = 0;
  for (size_t i = 0; i < eps_end.size(); ++i)
    largest = std::max(largest, eps_end[i]), Fxx = std::max(Fxx, F_end[4 * i]);
  std::printf(
      "strain_magnitude after the reset: largest %.3e (tolerance 1e-12) with F_xx up to "
      "%.4f\n",
      largest, Fxx);
  CHECK(largest < 1e-12);
  CHECK(Fxx > 1.15);
}

TEST_CASE("slope_failure measures a block moved rigidly: failed mass, depth, run-out, rest",
          "[slope]") {
  // The block moves at 0.5 m/s along x. Stage 1 (1 s) is before the reset; stage 2 resets the
  // displacement and moves on for 2 s (u = 1 m > moved_displacement = 0.5 m: the whole block is
  // the failed mass); stage 3 stops it (reset: [velocity]) for 1 s. Measured since stage 2's
  // start: the block's area 2 m^2, depth 1 m (its height), base at its bottom, front
  // 3.5 + 1 = 4.5 m against a toe at 3.5 m (run-out 1 m), the top 1 m above the bottom where
  // it now stands (at x = 4.1 m, off the particle lattice's midlines), at rest after 2 s (the end
  // of the last 0.5 s interval that moved), 90 % of the movement at 2 s (samples every 0.5 s: 0.75
  // m at 1.5 s, 1 m at 2 s).
  loam_test::TempDir d("slope_failure_block");
  const std::string yaml =
      block("[0.5, 0]",
            "time: {dt: 0.05}\n"
            "output: {every_time: 1}\n"
            "verify: {type: slope_failure, toe: 3.5, every: 0.5, surface_at: [4.1]}\n"
            "stages:\n"
            "  - {name: before, duration: 1}\n"
            "  - {name: slide, duration: 2, reset: [displacement]}\n"
            "  - {name: stop, duration: 1, reset: [velocity]}\n");
  auto r = loam_test::run_yaml(d.path, yaml);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const auto v = summary_of(d.path / "out")["verify"];
  INFO(v.dump(1));
  std::printf(
      "slope_failure on a rigid block: failed_volume %.12f (2), failure_depth %.12f (1), "
      "slip_base_height %.2e (0), runout %.12f (1), deposit_top_height %.12f (1), "
      "max_displacement %.12f (1), time_to_rest %.6f (2), time_to_90_percent %.6f (2)\n",
      v["failed_volume"].get<double>(), v["failure_depth"].get<double>(),
      v["slip_base_height"].get<double>(), v["runout"].get<double>(),
      v["deposit_top_height"].get<double>(), v["max_displacement"].get<double>(),
      v["time_to_rest"].get<double>(), v["time_to_90_percent"].get<double>());
  CHECK(v["failed_volume"].get<double>() == Approx(2).epsilon(1e-12));
  CHECK(v["failure_depth"].get<double>() == Approx(1).epsilon(1e-12));
  CHECK(std::abs(v["slip_base_height"].get<double>()) < 1e-12);
  CHECK(v["runout"].get<double>() == Approx(1).epsilon(1e-12));
  CHECK(v["deposit_top_height"].get<double>() == Approx(1).epsilon(1e-12));
  CHECK(v["moved_mass_top_height"].get<double>() == Approx(1).epsilon(1e-12));
  // Since the reset only (1.5 m since t = 0).
  CHECK(v["max_displacement"].get<double>() == Approx(1).epsilon(1e-12));
  CHECK(v["time_to_rest"].get<double>() == Approx(2).epsilon(1e-9));
  CHECK(v["time_to_90_percent"].get<double>() == Approx(2).epsilon(1e-9));
  CHECK(v["final_interval_speed"].get<double>() < 1e-12);
  // The series starts at the reset.
  const auto& t = v["series"]["time_since_reset"];
  REQUIRE(t.size() >= 6);
  CHECK(t[0].get<double>() < 0.1);
}

TEST_CASE(
    "slope_failure: a failed mass still moving at the end is not at rest, below the "
    "threshold there is no failed mass",
    "[slope]") {
  // 0.5 m/s for 2 s, no reset: the block (all of it failed, 1 m > 0.5 m) still moves at the
  // end: time_to_rest is NaN (null). With moved_displacement 1.5 m nothing has failed.
  loam_test::TempDir d("slope_failure_moving");
  auto run = [&](const std::string& extra) {
    auto r = loam_test::run_yaml(d.path,
                                 block("[0.5, 0]",
                                       "time: {end: 2, dt: 0.05}\n"
                                       "verify: {type: slope_failure, toe: 3.5, every: 0.5" +
                                           extra + "}\n"),
                                 "--overwrite");
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    return summary_of(d.path / "out")["verify"];
  };
  const auto v = run("");
  INFO(v.dump(1));
  CHECK(v["failed_volume"].get<double>() == Approx(2).epsilon(1e-12));
  CHECK(v["time_to_rest"].is_null());
  CHECK(v["final_interval_speed"].get<double>() == Approx(0.5).epsilon(1e-9));
  CHECK(!v.contains("deposit_top_height"));  // no surface_at
  const auto none = run(", moved_displacement: 1.5");
  INFO(none.dump(1));
  CHECK(none["failed_volume"].get<double>() == 0.0);
  CHECK(none["failure_depth"].get<double>() == 0.0);
  CHECK(none["runout"].is_null());
  CHECK(none["slip_base_height"].is_null());
}

TEST_CASE("slope_failure and strain_magnitude: bad input gives located errors", "[slope]") {
  loam_test::TempDir d("slope_failure_bad");
  struct Case {
    std::string yaml, message;
  };
  const std::vector<Case> cases = {
      {block("[0, 0]", "time: {end: 1}\nverify: {type: slope_failure}\n"),
       "verify.toe: missing required key"},
      {block("[0, 0]",
             "time: {end: 1}\nverify: {type: slope_failure, toe: 1, surface_at: [1, "
             "2]}\n"),
       "verify.surface_at: give 1 coordinate(s)"},
      {block("[0, 0]", "time: {end: 1}\nverify: {type: slope_failure, toe: 1, body: rock}\n"),
       "verify.body: unknown body 'rock'"},
      {block("[0, 0]",
             "time: {end: 1}\nverify: {type: slope_failure, toe: 1, moved_displacement: 0}\n"),
       "verify.moved_displacement"},
      {block("[0, 0]", "time: {end: 1}\noutput: {fields: [strain_magnitud]}\n"),
       "did you mean 'strain_magnitude'"},
  };
  for (const auto& c : cases) {
    auto r = loam_test::run_yaml(d.path, c.yaml);
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.find(c.message) != std::string::npos);
    CHECK(r.output.find("run.yaml:") != std::string::npos);
    CHECK(!fs::exists(d.path / "out"));
  }
}
