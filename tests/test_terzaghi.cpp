// Terzaghi one-way consolidation (plugins/terzaghi.hpp series, plugins/terzaghi.cpp reference;
// VERIFICATION.md C). The series are checked against classic tables, their own limits and
// boundary conditions and each other; the reference plugin is checked by filling the
// pore_pressure field with known values (no two-phase scheme exists yet) and through the CLI
// for its located errors.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "cli.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "plugins/terzaghi.hpp"
#include "sim_helpers.hpp"

using loam::terzaghi_degree;
using loam::terzaghi_pressure;

TEST_CASE("terzaghi: degree of consolidation against tabulated values", "[reference][unit]") {
  // Reference: classic U(T_v) table for a uniform initial excess pore pressure (e.g. Craig's
  // Soil Mechanics, Table 7.1 / Terzaghi 1943), 4 decimals. Tolerance 1e-4 (table rounding 5e-5).
  const std::vector<std::pair<double, double>> table = {
      {0.05, 0.2523}, {0.1, 0.3568}, {0.2, 0.5041}, {0.5, 0.7640}, {1.0, 0.9313}};
  for (auto [T, U] : table) {
    const double u = terzaghi_degree(T);
    std::printf("terzaghi: U(%.2f) = %.6f (table %.4f, diff %.1e)\n", T, u, U, u - U);
    CHECK(std::fabs(u - U) < 1e-4);
  }
}

TEST_CASE("terzaghi: small time factors follow U = 2 sqrt(T/pi)", "[reference][unit]") {
  // Reference: the short-time solution U = 2 sqrt(T/pi), exact up to terms of order
  // exp(-1/T) (at T = 0.05: 1e-10 relative). Tolerance: 1e-9 relative for 1e-8 <= T <= 0.05, by
  // both the chosen series (images below T = 0.01) and the Fourier series alone, which then
  // needs up to ~1.5e4 terms: the point of its truncation criterion.
  double worst = 0, worst_fourier = 0;
  for (double T : {1e-8, 1e-6, 1e-4, 1e-3, 1e-2, 0.02, 0.05}) {
    const double ref = 2 * std::sqrt(T / M_PI);
    int terms = 0;
    const double uf = loam::terzaghi_degree_fourier(T, &terms);
    worst = std::max(worst, std::fabs(terzaghi_degree(T) / ref - 1));
    worst_fourier = std::max(worst_fourier, std::fabs(uf / ref - 1));
    std::printf("terzaghi: T = %g: U = %.12g, 2 sqrt(T/pi) = %.12g, Fourier %.12g (%d terms)\n", T,
                terzaghi_degree(T), ref, uf, terms);
  }
  std::printf("terzaghi: small T: max rel err %.2e (Fourier alone %.2e)\n", worst, worst_fourier);
  CHECK(worst < 1e-9);
  CHECK(worst_fourier < 1e-9);
  CHECK(terzaghi_degree(0.0) == 0.0);
}

TEST_CASE("terzaghi: the Fourier and image series agree", "[reference][unit]") {
  // Reference: two independent forms of the same solution (plugins/terzaghi.hpp). Where both
  // converge (1e-4 <= T <= 2) they must agree. Tolerance: 1e-13 absolute on p/p0 and U.
  double worst_p = 0, worst_u = 0;
  int most_f = 0, most_i = 0;
  for (double T : {1e-4, 1e-3, 0.005, 0.01, 0.05, 0.1, 0.2, 0.5, 1.0, 2.0}) {
    for (int j = 0; j <= 100; ++j) {
      const double zeta = j / 100.0;
      int tf = 0, ti = 0;
      const double pf = loam::terzaghi_pressure_fourier(zeta, T, &tf);
      const double pi = loam::terzaghi_pressure_images(zeta, T, &ti);
      worst_p = std::max(worst_p, std::fabs(pf - pi));
      most_f = std::max(most_f, tf), most_i = std::max(most_i, ti);
    }
    worst_u = std::max(
        worst_u, std::fabs(loam::terzaghi_degree_fourier(T) - loam::terzaghi_degree_images(T)));
  }
  int t4 = 0, t2 = 0, t1 = 0;
  loam::terzaghi_pressure_fourier(0.5, 1e-4, &t4);
  loam::terzaghi_pressure_fourier(0.5, 1e-2, &t2);
  loam::terzaghi_pressure_fourier(0.5, 1.0, &t1);
  std::printf(
      "terzaghi: Fourier vs images: max |dp| %.2e, max |dU| %.2e; Fourier terms: %d at "
      "T = 1e-4, %d at 1e-2, %d at 1; image terms at most %d\n",
      worst_p, worst_u, t4, t2, t1, most_i);
  CHECK(worst_p < 1e-13);
  CHECK(worst_u < 1e-13);
}

TEST_CASE("terzaghi: drained top, impermeable base, undrained start", "[reference][unit]") {
  // Reference: the boundary and initial conditions of the problem. p(z' = 0) = 0 to 1e-15;
  // dp/dzeta at the base zeta = 1 by a one-sided second-order difference with h = 1e-4 (exact
  // 0; truncation ~h^2 |p'''|, rounding ~1e-12): |dp/dzeta| < 1e-6 while the interior slope is
  // O(1); p -> 1 inside as T -> 0 (1e-15 at T = 1e-10, zeta >= 0.01; 1e-6 at T = 1e-6, zeta = 0.1).
  double top = 0, base = 0;
  for (double T : {0.0, 1e-8, 1e-4, 0.005, 0.01, 0.05, 0.1, 0.2, 0.5, 1.0, 3.0}) {
    top = std::max(top, std::fabs(terzaghi_pressure(0.0, T)));
    if (T > 0) {
      const double h = 1e-4;
      const double d = (3 * terzaghi_pressure(1, T) - 4 * terzaghi_pressure(1 - h, T) +
                        terzaghi_pressure(1 - 2 * h, T)) /
                       (2 * h);
      base = std::max(base, std::fabs(d));
    }
  }
  const double slope = (terzaghi_pressure(0.3, 0.1) - terzaghi_pressure(0.2, 0.1)) / 0.1;
  double inside = 0;
  for (double zeta : {0.01, 0.1, 0.5, 0.9, 1.0})
    inside = std::max(inside, std::fabs(terzaghi_pressure(zeta, 1e-10) - 1));
  const double p6 = terzaghi_pressure(0.1, 1e-6);
  std::printf(
      "terzaghi: max |p(top)| %.2e, max |dp/dzeta(base)| %.2e (interior slope %.3f), "
      "max |p - 1| at T = 1e-10 %.2e, p(0.1, 1e-6) - 1 = %.2e\n",
      top, base, slope, inside, p6 - 1);
  CHECK(top < 1e-15);
  CHECK(base < 1e-6);
  CHECK(slope > 0.5);
  CHECK(inside < 1e-15);
  CHECK(std::fabs(p6 - 1) < 1e-6);
  CHECK(terzaghi_pressure(0.5, 0.0) == 1.0);
}

TEST_CASE("terzaghi: U equals one minus the mean pore pressure", "[reference][unit]") {
  // Reference: U(T) = 1 - int_0^1 p/p0 dzeta, the integral by composite Simpson with 4000
  // intervals (error ~1e-14 for T >= 0.01). Checks the U and p series against each other.
  // Tolerance: 1e-11.
  double worst = 0;
  for (double T : {0.01, 0.05, 0.1, 0.2, 0.5, 1.0}) {
    const int n = 4000;
    double s = terzaghi_pressure(0, T) + terzaghi_pressure(1, T);
    for (int i = 1; i < n; ++i) s += (i % 2 ? 4 : 2) * terzaghi_pressure(double(i) / n, T);
    const double mean = s / (3.0 * n);
    worst = std::max(worst, std::fabs(1 - mean - terzaghi_degree(T)));
  }
  std::printf("terzaghi: |1 - mean(p) - U| max %.2e\n", worst);
  CHECK(worst < 1e-11);
}

namespace {

/// A D-dimensional column 1 m high (base at 0, 20 particles along the last axis), no verify.
template <int D>
std::string column_scene() {
  auto vec = [](double lateral, double vertical) {
    std::string s = "[";
    for (int d = 0; d < D; ++d)
      s += (d ? ", " : "") + std::to_string(d == D - 1 ? vertical : lateral);
    return s + "]";
  };
  return "grid: {extent: " + vec(0.2, 1.2) +
         ", cell_size: 0.1}\n"
         "bodies:\n  - name: column\n    generator: {type: box, min: " +
         vec(0, 0) + ", max: " + vec(0.1, 1.0) +
         "}\n    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1.0e7, nu: 0, density: 2000}\n"
         "time: {end: 1}\n";
}

/// Fill pore_pressure with p0 * exact(zeta0, T), zeta0 = 1 - z0 (initial positions, H = 1), then
/// compress the column uniformly by `strain` (z -> (1 - strain) z) so that the current-geometry
/// zeta of each particle equals its initial one.
template <int D>
void fill(loam::Simulation<D>& sim, int pore, const std::vector<double>& z0, double p0, double T,
          double strain) {
  auto& P = sim.particles;
  for (size_t i = 0; i < P.size(); ++i) {
    P.col(pore)[i] = p0 * terzaghi_pressure(1 - z0[P.id[i]], T);
    P.col(P.position, D - 1)[i] = (1 - strain) * z0[P.id[i]];  // volumes: uniform either way
  }
}

template <int D>
void check_reference_sampling() {
  // Reference: the pore_pressure field set to the exact Terzaghi values (so max_error is
  // rounding only, < 1e-14), with one particle off by +0.013 p0 at T = 0.1 (then max_error_T0.1
  // = 0.013 to 1e-12), on the initial geometry at T = 0.1 and on a column compressed by 10% at
  // T = 0.5 (zeta from the current top and height: error still < 1e-14). The degree-of-
  // consolidation error is then the midpoint-rule error of the particle mean (20 particles per
  // column, <= 5e-4) plus the perturbation's share 0.013/20 at T = 0.1. T = 1 is never reached:
  // its metrics and the worst-case ones are NaN. c_v = 0.01 m^2/s, H = 1 m, p0 = 1e4 Pa.
  auto sim = loam_test::make_simulation<D>(column_scene<D>());
  auto& P = sim->particles;
  const int pore = P.request({"pore_pressure", 1, "Pa", "excess pore pressure", {}});
  std::vector<double> z0(P.size());
  for (size_t i = 0; i < P.size(); ++i) z0[P.id[i]] = P.col(P.position, D - 1)[i];
  auto ref =
      loam_test::make_reference<D>(*sim,
                                   "{type: terzaghi, load: 1.0e4, consolidation_coefficient: 0.01, "
                                   "time_factors: [0.1, 0.5, 1]}");
  const double cv = 0.01, p0 = 1e4;
  // Steps before T = 0.1 sample nothing.
  sim->time = 0.05 / cv;
  ref->sample(*sim);
  fill<D>(*sim, pore, z0, p0, 0.1, 0.0);
  P.col(pore)[P.size() / 3] += 0.013 * p0;
  sim->time = 0.1 / cv * (1 + 1e-14);
  ref->sample(*sim);
  fill<D>(*sim, pore, z0, p0, 0.5, 0.1);
  sim->time = 0.5 / cv;
  ref->sample(*sim);
  auto m = ref->metrics(*sim);
  std::printf(
      "terzaghi reference %dD (%zu particles): max_error_T0.1 = %.15f (0.013), "
      "max_error_T0.5 = %.2e, U errors %.2e / %.2e, max_error %s, drainage_length %g\n",
      D, P.size(), m["max_error_T0.1"], m["max_error_T0.5"], m["consolidation_degree_error_T0.1"],
      m["consolidation_degree_error_T0.5"],
      std::isnan(m["max_error"]) ? "NaN (T = 1 not reached)" : "set", m["drainage_length"]);
  CHECK(std::fabs(m["max_error_T0.1"] - 0.013) < 1e-12);
  CHECK(m["max_error_T0.5"] < 1e-14);
  CHECK(m["consolidation_degree_error_T0.1"] < 5e-4 + 0.013 / 20);
  CHECK(m["consolidation_degree_error_T0.5"] < 5e-4);
  CHECK(std::isnan(m["max_error_T1"]));
  CHECK(std::isnan(m["max_error"]));
  CHECK(std::isnan(m["consolidation_degree_error"]));
  CHECK(m["drainage_length"] == Approx(1.0).epsilon(1e-12));
  // Reaching T = 1 completes the set: the worst cases are then the T = 0.1 values.
  // The step that passes T = 1 ends at T = 1.2: the exact values are those of T = 1.2.
  fill<D>(*sim, pore, z0, p0, 1.2, 0.0);
  sim->time = 1.2 / cv;
  ref->sample(*sim);
  m = ref->metrics(*sim);
  CHECK(m["max_error"] == m["max_error_T0.1"]);
  CHECK(m["consolidation_degree_error"] >= m["consolidation_degree_error_T0.5"]);
}

}  // namespace

TEST_CASE("terzaghi: the reference samples pore_pressure at the requested time factors",
          "[reference][unit]") {
  check_reference_sampling<1>();
  check_reference_sampling<2>();
}

TEST_CASE("terzaghi: bad parameters and a single-phase run give the located error",
          "[reference][unit]") {
  // Reference: the standard FILE:LINE:COL: error: path: message, exit code 2, nothing written.
  loam_test::TempDir dir("terzaghi_bad");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "run.yaml";
  struct Case {
    std::string verify, line;
  };
  const std::vector<Case> cases = {
      {"{type: terzaghi, load: 1.0e4, consolidation_coefficient: 10}",
       ":10:9: error: verify: terzaghi needs a two-phase scheme (no pore_pressure field)"},
      {"{type: terzaghi, load: -1.0e4, consolidation_coefficient: 10}",
       ":10:32: error: verify.load: -10000 is out of range (0, inf) Pa"},
      {"{type: terzaghi, load: 1.0e4, consolidation_coefficient: 10, time_factors: [0.1, -0.2]}",
       ":10:90: error: verify.time_factors.1: -0.2 is out of range (0, inf)"},
      {"{type: terzaghi, load: 1.0e4, consolidation_coefficient: 10, time_factors: []}",
       ":10:84: error: verify.time_factors: give at least one time factor"},
      {"{type: terzaghi, load: 1.0e4}",
       ":10:9: error: verify.consolidation_coefficient: missing required key "
       "'consolidation_coefficient' (c_v = k M / gamma_w (k hydraulic conductivity, M constrained "
       "modulus), m^2/s)"},
  };
  for (const auto& k : cases) {
    std::ofstream(cfg) << "grid:\n  extent: [1.2]\n  cell_size: 0.1\nbodies:\n  - name: column\n"
                          "    generator: {type: box, min: [0], max: [1]}\n"
                          "    material: {type: linear_elastic, E: 1.0e7, nu: 0, density: 2000}\n"
                          "time:\n  end: 0.1\nverify: "
                       << k.verify << "\n";
    auto r = loam_test::run_loam("run " + cfg.string() + " --quiet --out " +
                                 (dir.path / "out").string());
    std::printf("%s", r.output.c_str());
    CHECK(r.exit_code == 2);
    CHECK(r.output == cfg.string() + k.line + "\n");
    CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
  }
}
