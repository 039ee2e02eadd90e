// Seed 002 dynamic (oedometric) consolidation (docs/verification.md C, "Seed 002"; seed paper
// section 3.2, Figs. 5-6): configs/seed002_dynamic_consolidation.yaml (fixed, impervious base)
// and configs/seed002_dynamic_consolidation_absorbing.yaml (impermeable viscous absorbing base),
// through the real CLI. Late times against Terzaghi's series (c_v = kappa M / mu_w = 1 m^2/s,
// T = t / 1 s); early times against the wave physics of the saturated column (Biot), computed
// here from the config's parameters (biot() below): with the fixed base the undrained wave
// reflects (the base pore pressure doubles) and the column rings in its damped fundamental mode;
// with the absorbing base the wave leaves, and the column is close to the static solution at
// t1 = 0.02 s.
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <complex>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "cli.hpp"

namespace {

constexpr double kP0 = 1e3;  // step load (Pa)

/// The wave references of the column, from the config's parameters (1D, nu = 0, incompressible
/// grains, no gravity). Equations (x up from the base, u solid and w water displacement,
/// p pore pressure compression +, Q = n^2 mu_w / kappa the Darcy drag per mixture volume):
///   (1 - n) rho_s u'' = M u_xx - (1 - n) p_x + Q (w' - u')
///   n rho_w w''       =        - n p_x       - Q (w' - u')
///   p = -(K_w / n) ((1 - n) u_x + n w_x)
/// i.e. stiffness K11 = M + (1 - n)^2 K_w / n, K12 = (1 - n) K_w, K22 = n K_w on (u, w).
/// - Locked phases (Q -> inf, the undrained limit): c_0 = sqrt((M + K_w/n) / rho_sat), Skempton
///   B = (K_w/n) / (K_w/n + M).
/// - Free phases (Q -> 0, the front of a step): c_inf, the fast root of
///   det(K - c^2 diag(m_s, m_w)) = 0. The step front (which contains both) reaches the base
///   between H/c_inf and H/c_0.
/// - Fixed impervious base (u = w = 0) and drained, constantly loaded top (p = 0, sigma' = 0
///   as perturbations): the modes sin(k x) with cos(k H) = 0; the fundamental k = pi/(2H) has
///   the complex frequency omega = omega_r - i gamma of the fast root of
///   det(k^2 K - omega^2 diag(m_s, m_w) - i omega Q [[1, -1], [-1, 1]]) = 0 (Newton from c_0 k):
///   period 2 pi / omega_r, amplitude ratio per period exp(-2 pi gamma / omega_r).
struct Medium {
  double M = 0, rho_s = 0, n = 0, Kw = 0, rho_w = 0, Q = 0, H = 0;
};

Medium medium(const std::string& config) {
  const YAML::Node cfg = YAML::LoadFile(std::string(LOAM_SOURCE_DIR) + "/configs/" + config);
  const YAML::Node sch = cfg["scheme"], drag = sch["drag"], body = cfg["bodies"][0];
  const YAML::Node mat = body["material"];
  REQUIRE(mat["nu"].as<double>() == 0.0);  // constrained modulus M = E
  Medium m;
  m.M = mat["E"].as<double>();
  m.rho_s = mat["density"].as<double>();
  m.n = sch["porosity"].as<double>();
  m.Kw = sch["water_bulk_modulus"].as<double>();
  m.rho_w = drag["density"].as<double>();
  m.Q = m.n * m.n * drag["viscosity"].as<double>() / drag["intrinsic_permeability"].as<double>();
  m.H = body["generator"]["max"][0].as<double>() - body["generator"]["min"][0].as<double>();
  return m;
}

struct Biot {
  double B = 0, c0 = 0, cinf = 0, rho_sat = 0, period = 0, decay = 0, H = 0;
};

Biot biot(const Medium& m) {
  Biot b;
  b.H = m.H;
  const double n = m.n, Kw = m.Kw, ms = (1 - n) * m.rho_s, mw = n * m.rho_w, Q = m.Q;
  const double K11 = m.M + (1 - n) * (1 - n) * Kw / n, K12 = (1 - n) * Kw, K22 = n * Kw;
  b.rho_sat = ms + mw;
  b.B = (Kw / n) / (Kw / n + m.M);
  b.c0 = std::sqrt((m.M + Kw / n) / b.rho_sat);
  const double qa = ms * mw, qb = -(K11 * mw + K22 * ms), qc = K11 * K22 - K12 * K12;
  b.cinf = std::sqrt((-qb + std::sqrt(qb * qb - 4 * qa * qc)) / (2 * qa));
  using C = std::complex<double>;
  const double k = M_PI / (2 * b.H);
  const C I(0, 1);
  C w(b.c0 * k, 0);
  for (int it = 0; it < 200; ++it) {
    const C a1 = k * k * K11 - w * w * ms - I * w * Q, a2 = k * k * K22 - w * w * mw - I * w * Q;
    const C a3 = k * k * K12 + I * w * Q;
    const C f = a1 * a2 - a3 * a3;
    const C df = (-2.0 * w * ms - I * Q) * a2 + a1 * (-2.0 * w * mw - I * Q) - 2.0 * a3 * I * Q;
    const C step = f / df;
    w -= step;
    if (std::abs(step) < 1e-15 * std::abs(w)) break;
  }
  b.period = 2 * M_PI / w.real();
  b.decay = std::exp(2 * M_PI * w.imag() / w.real());
  return b;
}

Biot biot(const std::string& config) {
  return biot(medium(config));
}

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
  /// Largest |p/p0 - level| over [t0, t1].
  double deviation(double level, double t0, double t1) const {
    auto [lo, hi] = range(t0, t1);
    return std::max(hi - level, level - lo);
  }
  /// Times in [t0, t1] where p/p0 rises through `level` (linear interpolation between samples).
  std::vector<double> rising(double level, double t0, double t1) const {
    std::vector<double> out;
    for (size_t i = 1; i < t.size(); ++i) {
      const double a = p[i - 1] / kP0, b = p[i] / kP0;
      if (t[i - 1] >= t0 && t[i] <= t1 && a < level && b >= level)
        out.push_back(t[i - 1] + (level - a) / (b - a) * (t[i] - t[i - 1]));
    }
    return out;
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

/// Late times (t = 0.5 and 1 s) against the incompressible Terzaghi series (the task's target is
/// 0.03). Measured errors (both bases alike), cell 0.025 / 0.0125 / 0.00625 m:
///   T = 0.5: 0.0039 / 0.0021 / 0.0015,   T = 1: 0.0018 / 0.0016 / 0.0015.
/// Part of it is not discretisation: the reference is for incompressible water, the model has
/// B = 0.990 and c_v' = 0.990 m^2/s, whose series differs from Terzaghi's by up to 0.0008
/// (T = 0.5) and 0.0016 (T = 1) (the T = 1 floor above). Tolerances: 0.005 / 0.0025 at 0.025 m,
/// 0.003 / 0.002 on the refined columns.
void check_late_times(const Seed002& r, double tol05, double tol1) {
  CHECK(r.verify["max_error_T0.5"].get<double>() <= tol05);
  CHECK(r.verify["max_error_T1"].get<double>() <= tol1);
}

/// The fixed base's wave checks, against biot(): (1) the front reaches the base (p rises
/// through B p0, half the doubled value) between (H - h)/c_inf (h: one pore pressure per cell)
/// and H/c_0; measured 1.47 / 1.44 / 1.41 ms in [1.32, 1.52]. (2) Reflected at the rigid
/// impervious base the pore pressure doubles to 2 B p0 = 1.980 p0: first peak (0-5 ms) within
/// 0.02 of it (measured +0.013 / +0.009 / +0.005 p0: the step front's overshoot, shrinking with
/// h). (3) The column rings in its damped fundamental mode: mean period of the rises through
/// B p0 in 10-50 ms against the Biot period 6.0327 ms within 0.3 % (measured +0.08 to +0.09 % at
/// every h: the crossings shift as consolidation lowers the mean), and the swing (max - min per
/// cycle) decays per period as exp(-2 pi gamma/omega_r) = 0.7998: geometric mean over the
/// cycles that start in 10-56 ms within 0.005 (measured 0.7980 / 0.7979 / 0.7981).
void check_fixed_base_wave(const Seed002& r, const Biot& b, double h) {
  const auto front = r.rising(b.B, 0, 0.005);
  REQUIRE(!front.empty());
  const double lo = (b.H - h) / b.cinf, hi = b.H / b.c0;
  const double peak = r.range(0, 0.005).second;
  const auto ups = r.rising(b.B, 0.01, 0.05);
  REQUIRE(ups.size() >= 3);
  const double period = (ups.back() - ups.front()) / double(ups.size() - 1);
  const auto cyc = r.rising(b.B, 0.01, 0.056);
  REQUIRE(cyc.size() >= 3);
  std::vector<double> swing;
  for (size_t i = 1; i < cyc.size(); ++i) {
    auto [mn, mx] = r.range(cyc[i - 1], cyc[i]);
    swing.push_back(mx - mn);
  }
  const double decay = std::pow(swing.back() / swing.front(), 1.0 / double(swing.size() - 1));
  std::printf(
      "  fixed base: front at the base %.4f ms (bracket [%.4f, %.4f] = [(H - h)/c_inf, H/c_0], "
      "c_inf %.1f, c_0 %.1f m/s); first peak %.4f p0 (2B = %.4f, %+.4f); period %.4f ms (Biot "
      "fundamental %.4f, %+.2e); decay per period %.4f (Biot %.4f, %+.4f, %zu cycles)\n",
      front[0] * 1e3, lo * 1e3, hi * 1e3, b.cinf, b.c0, peak, 2 * b.B, peak - 2 * b.B, period * 1e3,
      b.period * 1e3, period / b.period - 1, decay, b.decay, decay - b.decay, swing.size());
  CHECK(front[0] >= lo);
  CHECK(front[0] <= hi);
  CHECK(std::fabs(peak - 2 * b.B) <= 0.02);
  CHECK(std::fabs(period / b.period - 1) <= 3e-3);
  CHECK(std::fabs(decay - b.decay) <= 0.005);
}

/// The absorbing base's wave checks: (1) the front reaches the base (p rises through B p0 / 2)
/// in the bracket of check_fixed_base_wave (measured 1.44 / 1.42 / 1.40 ms). (2) Not
/// reflected: the base pore pressure never exceeds B p0 by more than 0.06 p0 (measured peak
/// +0.052 / +0.032 / +0.026 p0: the step front's overshoot; a reflection would add B p0) and
/// stays within 0.015 p0 of B p0 over 10-20 ms (undrained there: Terzaghi's base value at
/// T = 0.02 is 1 - 1e-6; measured 0.0118 / 0.0116 / 0.0097). (3) The dashpot carries the load
/// by a rigid drift: at t = 1 s the base velocity is -p0 / (rho_sat c_u) (the dashpot's
/// impedance from the config: 2344.546 * 656.34) within 1e-3 (measured 2.4e-4 / 1.1e-4 /
/// 0.4e-4: the remaining consolidation settlement rate).
void check_absorbing_base_wave(const Seed002& r, const Biot& b, double h) {
  const auto front = r.rising(b.B / 2, 0, 0.005);
  REQUIRE(!front.empty());
  const double lo = (b.H - h) / b.cinf, hi = b.H / b.c0;
  const double peak = r.range(0, 1).second, dev = r.deviation(b.B, 0.01, 0.02);
  const double drift = -kP0 / (2344.546 * 656.34);
  std::printf(
      "  absorbing base: front at the base %.4f ms (bracket [%.4f, %.4f]); max p/p0 %.4f (B = "
      "%.4f, %+.4f); max |p/p0 - B| in 10-20 ms %.4f; velocity at 1 s %.5g m/s (-p0/Z = %.5g, "
      "%+.1e)\n",
      front[0] * 1e3, lo * 1e3, hi * 1e3, peak, b.B, peak - b.B, dev, r.v.back(), drift,
      r.v.back() / drift - 1);
  CHECK(front[0] >= lo);
  CHECK(front[0] <= hi);
  CHECK(peak - b.B <= 0.06);
  CHECK(dev <= 0.015);
  CHECK(std::fabs(r.v.back() / drift - 1) <= 1e-3);
}

}  // namespace

TEST_CASE("biot: the column's wave speeds and damped fundamental mode", "[reference][unit]") {
  // Checks biot() (the wave reference of the tests below) on what it must reproduce: seed 002's
  // c_0 = 656.34 m/s and rho_sat = 2344.546 kg/m^3 (the config's absorbing-base impedance,
  // to the config's rounding: 0.005 m/s, and 0.001 kg/m^3 as the grain density 2920.781 is
  // itself rounded) and B = (K_w/n)/(K_w/n + M) = 1e9/(1e9 + 1e7);
  // and the two limits of the mode: without drag (Q -> 0) the fast mode is undamped at the
  // free-phase speed, period 4H/c_inf; with the phases locked (Q -> inf) it is undamped at the
  // undrained speed, period 4H/c_0. Tolerances 1e-9 relative on the periods and 1e-6 on the
  // decay (at Q = 1e-6 and 1e16 Pa s/m^2 the damping is ~1e-10 and ~1e-8 per period).
  const Medium m = medium("seed002_dynamic_consolidation.yaml");
  const Biot b = biot(m);
  Medium free = m, locked = m;
  free.Q = 1e-6, locked.Q = 1e16;
  const Biot bf = biot(free), bl = biot(locked);
  std::printf(
      "biot: B = %.6f, c_0 = %.4f m/s, c_inf = %.4f m/s, rho_sat = %.4f; fundamental period "
      "%.6f ms, decay per period %.6f (4H/c_0 = %.6f, 4H/c_inf = %.6f ms); no drag %.9f ms "
      "(decay %.9f), locked %.9f ms (decay %.9f)\n",
      b.B, b.c0, b.cinf, b.rho_sat, b.period * 1e3, b.decay, 4 * b.H / b.c0 * 1e3,
      4 * b.H / b.cinf * 1e3, bf.period * 1e3, bf.decay, bl.period * 1e3, bl.decay);
  CHECK(std::fabs(b.c0 - 656.34) <= 0.005);
  CHECK(std::fabs(b.rho_sat - 2344.546) <= 0.001);
  CHECK(b.B == Approx(1e9 / (1e9 + 1e7)).epsilon(1e-12));
  CHECK(std::fabs(bf.period / (4 * b.H / b.cinf) - 1) < 1e-9);
  CHECK(std::fabs(bl.period / (4 * b.H / b.c0) - 1) < 1e-9);
  CHECK(std::fabs(bf.decay - 1) < 1e-6);
  CHECK(std::fabs(bl.decay - 1) < 1e-6);
  CHECK(b.decay < 0.9);  // seed 002's drag damps the mode
}

TEST_CASE("seed 002: fixed base: Terzaghi at late times, the undrained wave doubles at the base",
          "[verification][two_phase]") {
  // References: Terzaghi (late times, check_late_times) and the Biot wave references
  // (check_fixed_base_wave), at the config's cell 0.025 m. Was: late times 0.03, first peak
  // > 1.8 p0, swing > 0.5 p0 over 10-20 ms. At t1 = 0.02 s the column is still ringing (the
  // paper's "strong dynamic behaviour"; the t1 profile is 0.19 off Terzaghi): no Terzaghi check.
  const Seed002 r = run("seed002_dynamic_consolidation.yaml");
  check_late_times(r, 0.005, 0.0025);
  check_fixed_base_wave(r, biot("seed002_dynamic_consolidation.yaml"), 0.025);
}

TEST_CASE("seed 002: absorbing base: no reflection, near-static at t1 = 0.02 s, Terzaghi later",
          "[verification][two_phase]") {
  // References: Terzaghi (late times, check_late_times; and at t1) and the wave references
  // (check_absorbing_base_wave), at the config's cell 0.025 m. The absorbing base matches the
  // undrained impedance rho_sat c_u = 1.539e6 Pa s/m, so the wave is not reflected. At t1 the
  // paper's damped solution "almost adjusts the static solution": measured 0.0275 off
  // Terzaghi; tolerance 0.033 (was 0.05). It is looser than the refined scene's (full tier,
  // 0.013 at 0.00625 m) because of the drained-top boundary layer: at T = 0.02 it is
  // 2 sqrt(c_v t) = 0.28 m thick, 11 cells here; the error falls to 0.0152 and 0.0109 at 2x
  // and 4x finer cells, toward the compressible-water floor 1 - B = 0.0099 (the model starts
  // from B p0, the reference from p0).
  const Seed002 r = run("seed002_dynamic_consolidation_absorbing.yaml");
  check_late_times(r, 0.005, 0.0025);
  check_absorbing_base_wave(r, biot("seed002_dynamic_consolidation_absorbing.yaml"), 0.025);
  CHECK(r.verify["max_error_T0.02"].get<double>() <= 0.033);
}

TEST_CASE("seed 002: refined columns: both bases reach Terzaghi, the absorbing one already at t1",
          "[verification][two_phase][full]") {
  // References as above, at cell sizes 0.0125 and 0.00625 m (2x and 4x finer). Late times
  // within 0.003 (T = 0.5) and 0.002 (T = 1) for both bases (was 0.03); the wave checks; with
  // the absorbing base the t1 = 0.02 s profile within 0.018 at 0.0125 m and 0.013 at 0.00625 m
  // of Terzaghi (measured 0.0152 and 0.0109; was 0.02 at 0.00625 m only). Fixed base t1 errors
  // (still ringing, not checked): 0.177 and 0.172.
  for (const char* h : {"0.0125", "0.00625"}) {
    const std::string set = std::string("--set grid.cell_size=") + h;
    const Seed002 f = run("seed002_dynamic_consolidation.yaml", set);
    const Seed002 a = run("seed002_dynamic_consolidation_absorbing.yaml", set);
    check_late_times(f, 0.003, 0.002);
    check_late_times(a, 0.003, 0.002);
    check_fixed_base_wave(f, biot("seed002_dynamic_consolidation.yaml"), std::stod(h));
    check_absorbing_base_wave(a, biot("seed002_dynamic_consolidation_absorbing.yaml"),
                              std::stod(h));
    CHECK(a.verify["max_error_T0.02"].get<double>() <=
          (std::string(h) == "0.00625" ? 0.013 : 0.018));
  }
}
