// Seed 002 dynamic (oedometric) consolidation (VERIFICATION.md C, "Seed 002"; seed paper
// section 3.2, Figs. 5-6): configs/seed002_dynamic_consolidation.yaml (fixed, impervious base)
// and configs/seed002_dynamic_consolidation_absorbing.yaml (impermeable viscous absorbing base),
// through the real CLI. Late times against Terzaghi's series (c_v = kappa M / mu_w = 1 m^2/s,
// T = t / 1 s); early times by the wave physics the paper describes: with the fixed base the
// undrained wave reflects (the base pore pressure doubles) and keeps ringing at t1 = 0.02 s; with
// the absorbing base it leaves, and the column is close to the static solution at t1.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace {

constexpr double kP0 = 1e3;  // step load (Pa)

struct Seed002 {
  nlohmann::json verify;
  std::vector<double> t, p, v;  // base particle: time, pore pressure, solid velocity
  double wall = 0;
  long steps = 0;

  /// Largest and smallest base pore pressure / p0 over [t0, t1].
  std::pair<double, double> range(double t0, double t1) const {
    double lo = 1e300, hi = -1e300;
    for (size_t i = 0; i < t.size(); ++i)
      if (t[i] >= t0 && t[i] <= t1) lo = std::min(lo, p[i] / kP0), hi = std::max(hi, p[i] / kP0);
    return {lo, hi};
  }
};

Seed002 run(const std::string& config, const std::string& extra = "") {
  loam_test::TempDir dir("seed002");
  auto s = loam_test::run_scene(config, dir.path, "--threads 1 --set output.every_time=1 " + extra);
  Seed002 r;
  r.verify = s["verify"];
  r.wall = s["wall_seconds"];
  r.steps = s["steps"];
  std::ifstream in(dir.path / "probe_base.csv");
  std::string line;
  std::getline(in, line);
  REQUIRE(line == "step,time,pore_pressure,velocity");
  while (std::getline(in, line)) {
    std::stringstream ls(line);
    std::string c;
    double row[4];
    for (double& x : row) {
      std::getline(ls, c, ',');
      x = std::stod(c);
    }
    r.t.push_back(row[1]), r.p.push_back(row[2]), r.v.push_back(row[3]);
  }
  std::printf("%s %s: %ld steps, %.2f s wall\n", config.c_str(), extra.c_str(), r.steps, r.wall);
  for (const char* T : {"0.02", "0.1", "0.2", "0.5", "1"})
    std::printf("  t = %-4s s: max |p/p0 - Terzaghi| = %.4f, |U - U_Terzaghi| = %.4f\n", T,
                r.verify[std::string("max_error_T") + T].get<double>(),
                r.verify[std::string("consolidation_degree_error_T") + T].get<double>());
  return r;
}

/// Late times (t = 0.5 and 1 s): the target of the task, max |p/p0 - Terzaghi| <= 0.03. The
/// reference is the incompressible series; the compressible-water one (B = 0.990, c_v' = 0.990
/// m^2/s) differs by < 0.01 here (configs/seed002_dynamic_consolidation.yaml).
void check_late_times(const Seed002& r) {
  CHECK(r.verify["max_error_T0.5"].get<double>() <= 0.03);
  CHECK(r.verify["max_error_T1"].get<double>() <= 0.03);
}

}  // namespace

TEST_CASE("seed 002: fixed base: Terzaghi at late times, the undrained wave doubles at the base",
          "[verification][two_phase]") {
  // References: Terzaghi (late times, tolerance 0.03, see check_late_times). The undrained wave
  // (c_u = 656 m/s, arrival 1.5 ms) carries p = B p0 = 0.99 p0; reflected at the rigid
  // impervious base the pore pressure there doubles to 2 B p0 = 1.98 p0: required > 1.8 p0 in
  // the first 5 ms. At t1 = 0.02 s the paper's fixed-base solution "still has a strong dynamic
  // behaviour": required, the base pore pressure swings by more than 0.5 p0 over 10-20 ms.
  // Measured: late errors 0.0037 and 0.0018, peak 1.993 p0, swing 1.55 p0 (and the t1 profile
  // 0.19 off Terzaghi).
  const Seed002 r = run("seed002_dynamic_consolidation.yaml");
  check_late_times(r);
  const auto first = r.range(0, 0.005), ringing = r.range(0.01, 0.02);
  std::printf("  base: max p/p0 in 0-5 ms %.4f (2B = 1.980); p/p0 in 10-20 ms [%.3f, %.3f]\n",
              first.second, ringing.first, ringing.second);
  CHECK(first.second > 1.8);
  CHECK(ringing.second - ringing.first > 0.5);
}

TEST_CASE("seed 002: absorbing base: no reflection, near-static at t1 = 0.02 s, Terzaghi later",
          "[verification][two_phase]") {
  // References: Terzaghi (late times, tolerance 0.03). The absorbing base matches the undrained
  // impedance rho_sat c_u = 1.539e6 Pa s/m, so the wave is not reflected: the base pore pressure
  // stays below 1.1 p0 throughout (it doubles on a fixed base; the incident plateau is 0.99 p0
  // and the step front overshoots a few per cent) and swings by less than 0.05 p0 over 10-20 ms.
  // At t1 the paper's damped solution "almost adjusts the static solution": required within
  // 0.05 of Terzaghi (2.5x the seed 001 target: at T = 0.02 the drained-top boundary layer,
  // 2 sqrt(c_v t) = 0.28 m, spans 11 cells; the full tier refines). The dashpot carries the load
  // by a rigid drift: at t = 1 s the base velocity must be -p0 / (rho_sat c_u) = -6.498e-4 m/s
  // within 2 %. Measured: late errors 0.0039 and 0.0018, t1 error 0.0275, peak 1.042 p0, swing
  // 0.015 p0, velocity -6.497e-4 m/s.
  const Seed002 r = run("seed002_dynamic_consolidation_absorbing.yaml");
  check_late_times(r);
  const auto all = r.range(0, 1), ringing = r.range(0.01, 0.02);
  const double drift = -kP0 / (2344.546 * 656.34);
  std::printf(
      "  base: max p/p0 %.4f; p/p0 in 10-20 ms [%.4f, %.4f]; velocity at 1 s %.5g m/s "
      "(-p0/Z = %.5g)\n",
      all.second, ringing.first, ringing.second, r.v.back(), drift);
  CHECK(r.verify["max_error_T0.02"].get<double>() <= 0.05);
  CHECK(all.second < 1.1);
  CHECK(ringing.second - ringing.first < 0.05);
  CHECK(r.v.back() == Approx(drift).epsilon(0.02));
}

TEST_CASE("seed 002: refined columns: both bases reach Terzaghi, the absorbing one already at t1",
          "[verification][two_phase][full]") {
  // References as above, at cell sizes 0.0125 and 0.00625 m (2x and 4x finer). Targets: late
  // times within 0.03 for both bases; with the absorbing base the t1 = 0.02 s profile within
  // 0.02 of Terzaghi at 0.00625 m (the seed 001 target once the undrained wave has passed, which
  // it has, through the base, at 1.5 ms). Measured: t1 errors 0.0152 and 0.0109 (absorbing),
  // 0.177 and 0.172 (fixed).
  for (const char* h : {"0.0125", "0.00625"}) {
    const std::string set = std::string("--set grid.cell_size=") + h;
    const Seed002 f = run("seed002_dynamic_consolidation.yaml", set);
    const Seed002 a = run("seed002_dynamic_consolidation_absorbing.yaml", set);
    check_late_times(f);
    check_late_times(a);
    if (std::string(h) == "0.00625") CHECK(a.verify["max_error_T0.02"].get<double>() <= 0.02);
  }
}
