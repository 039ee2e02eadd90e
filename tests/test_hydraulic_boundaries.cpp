// Hydraulic face conditions of the two-phase scheme (plugins/boundaries/drained.cpp,
// impermeable.cpp, prescribed_pore_pressure.cpp; framework/hydraulic_face.hpp) on the seed-001
// Terzaghi column (configs/seed001_terzaghi.yaml: 1 m, c_v = 1.0194 m^2/s, p0 = 10 kPa, free
// drained top, fixed base), and the `phase` option of fixed/slip. References: Terzaghi's series
// (docs/verification.md C, plugins/references/terzaghi.hpp) and equilibrium.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "plugins/references/terzaghi.hpp"

namespace {

const double kCv = 1.0194, kP0 = 1e4;

struct Sample {
  double t, x, p, sxx;
};

struct ColumnRun {
  std::vector<std::vector<Sample>> probes;  // one time series per probe position
  nlohmann::json summary;
};

/// The Terzaghi column with `boundaries` replacing its own, `extra` appended to the config (a
/// `verify:` block there replaces the column's Terzaghi reference), and a probe at the particle
/// nearest each of `probe_x` (position, pore pressure, stress); `load`, if given, replaces the
/// column's traction entry.
ColumnRun run_column_probes(const std::string& boundaries, const std::vector<double>& probe_x,
                            double end, const std::string& extra = "",
                            const std::string& load = "") {
  loam_test::TempDir dir("hydraulic");
  std::filesystem::create_directories(dir.path);
  std::ifstream in(std::string(LOAM_SOURCE_DIR) + "/configs/seed001_terzaghi.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string cfg = text.str();
  const std::string own = "boundaries:\n  - {type: fixed, face: x-}\n";
  REQUIRE(cfg.find(own) != std::string::npos);
  cfg.replace(cfg.find(own), own.size(), "boundaries:\n" + boundaries);
  const std::string own_load = "  - {type: traction, body: column, face: x+, traction: [-1.0e4]}\n";
  REQUIRE(cfg.find(own_load) != std::string::npos);
  if (!load.empty()) cfg.replace(cfg.find(own_load), own_load.size(), load);
  // A verify block in `extra` replaces the config's own (the last block of the file).
  if (extra.rfind("verify:", 0) == 0 && cfg.find("\nverify:") != std::string::npos)
    cfg.erase(cfg.find("\nverify:") + 1);
  cfg += extra + "probes:\n";
  for (size_t k = 0; k < probe_x.size(); ++k)
    cfg += "  - {name: p" + std::to_string(k) + ", particle_near: [" + std::to_string(probe_x[k]) +
           "], fields: [position, pore_pressure, stress]}\n";
  std::ofstream(dir.path / "column.yaml") << cfg;
  auto r = loam_test::run_loam("run " + (dir.path / "column.yaml").string() +
                               " --quiet --threads 1 --out " + (dir.path / "out").string() +
                               " --set time.end=" + std::to_string(end) +
                               " --set output.every_time=" + std::to_string(end));
  if (r.exit_code != 0) FAIL("loam run failed:\n" << r.output);
  ColumnRun run;
  for (size_t k = 0; k < probe_x.size(); ++k) {
    std::vector<Sample> s;
    std::ifstream csv(dir.path / "out" / ("probe_p" + std::to_string(k) + ".csv"));
    std::string line;
    std::getline(csv, line);  // step,time,position,pore_pressure,stress_xx,...
    while (std::getline(csv, line)) {
      std::stringstream ls(line);
      std::string cell;
      std::vector<double> v;
      while (std::getline(ls, cell, ',')) v.push_back(std::stod(cell));
      s.push_back({v[1], v[2], v[3], v[4]});
    }
    run.probes.push_back(std::move(s));
  }
  std::ifstream js(dir.path / "out" / "summary.json");
  run.summary = nlohmann::json::parse(js);
  return run;
}

/// The same with one probe: its time series.
std::vector<Sample> run_column(const std::string& boundaries, double probe_x, double end) {
  return run_column_probes(boundaries, {probe_x}, end).probes[0];
}

const Sample& at(const std::vector<Sample>& s, double t) {
  size_t best = 0;
  for (size_t i = 0; i < s.size(); ++i)
    if (std::fabs(s[i].t - t) < std::fabs(s[best].t - t)) best = i;
  return s[best];
}

double mean_p(const std::vector<Sample>& s, double t0, double t1) {
  double sum = 0;
  int n = 0;
  for (const auto& x : s)
    if (x.t >= t0 && x.t <= t1) sum += x.p, ++n;
  return sum / n;
}

}  // namespace

TEST_CASE("hydraulic: fixed + drained base drains both ways (Terzaghi with H/2)",
          "[two_phase][hydraulic][verification]") {
  // Reference: two-way drainage of a 1 m column = the one-way series on a 0.5 m drainage
  // length, T' = c_v t / 0.5^2, the mid-plane being the impermeable symmetry plane. Probes at
  // the mid particle and at the particles next to the base and the top. Target as the Terzaghi
  // column: |p/p0 - exact| <= 0.02 at the mid particle at T' = 0.2, 0.5, 1 (earlier the
  // undrained wave still rings: the open base does not reflect it like the fixed one), and
  // base and top particles within 0.02 p0 of each other (symmetry).
  const std::string b = "  - {type: fixed, face: x-}\n  - {type: drained, face: x-}\n";
  const double end = 1.0 * 0.25 / kCv + 1e-3;
  auto mid = run_column(b, 0.5, end), base = run_column(b, 0.0, end), top = run_column(b, 1.0, end);
  for (double T : {0.2, 0.5, 1.0}) {
    const double t = T * 0.25 / kCv;
    const Sample& m = at(mid, t);
    const double zeta = 1 - std::fabs(m.x - 0.5) / 0.5;  // from the nearer drained face
    const double exact = loam::terzaghi_pressure(zeta, kCv * m.t / 0.25);
    const double e = std::fabs(m.p / kP0 - exact);
    const double asym = std::fabs(at(base, t).p - at(top, t).p) / kP0;
    std::printf(
        "two-way drainage T' = %.1f: mid p/p0 = %.4f, exact %.4f, error %.4f; "
        "|p_base - p_top|/p0 = %.4f\n",
        T, m.p / kP0, exact, e, asym);
    CHECK(e <= 0.02);
    CHECK(asym <= 0.02);
  }
}

TEST_CASE("hydraulic: a fixed, drained base drains like a free drained top (mirror image)",
          "[two_phase][hydraulic][verification]") {
  // The Terzaghi column drained through its fixed base, top sealed (impermeable) and loaded, is
  // the mirror image of the column with a free drained top and a fixed impermeable base.
  // Reference: Terzaghi's series p/p0(z'/H, T) with z' the distance from the drained face,
  // T = c_v t / H^2, at t = 0.3 s (T = 0.306), for the cells 0, 2 and 8 from the drained face
  // (pressure_smoothing: cell gives each particle its cell's mean, so compare at the cell
  // centres z' = 0.0125, 0.0625, 0.2125 m). The free top meets it within 6e-4 p0; target for
  // both: 0.005 p0. Before the drag re-solve of the released water the base was
  // -62 / 408 / 1797 Pa against 118 / 588 / 1965 (0.018 p0 off: the water leaving the fixed
  // base was dragged by the solve's free-solid velocity) and settled 2.5 % more than the top.
  // Settlement: the two columns' final_settlement within 1 % of each other. The same for the
  // three ways of writing a drained fixed base: fixed + drained, fixed with phase: solid, and
  // fixed + prescribed_pore_pressure 0 (all three were off before).
  const double end = 0.3, h = 0.025;
  const std::vector<double> cells = {0, 2, 8};
  const std::string settle = "verify: {type: settlement, load: 1.0e4}\n";
  std::vector<double> base_x, top_x;
  for (double c : cells) {
    base_x.push_back((c + 0.25) * h);  // the lower particle of the cell
    top_x.push_back(1.0 - (c + 0.25) * h);
  }
  auto top = run_column_probes("  - {type: fixed, face: x-}\n", top_x, end, settle);
  // Three ways to write a fixed, drained base (the water passes the held face).
  for (const char* drained_base :
       {"  - {type: fixed, face: x-}\n  - {type: drained, face: x-}\n",
        "  - {type: fixed, face: x-, phase: solid}\n",
        "  - {type: fixed, face: x-}\n"
        "  - {type: prescribed_pore_pressure, face: x-, pressure: 0}\n"}) {
    std::printf("drained base written as\n%s", drained_base);
    auto base = run_column_probes(std::string(drained_base) + "  - {type: impermeable, face: x+}\n",
                                  base_x, end, settle);
    for (size_t k = 0; k < cells.size(); ++k) {
      const double zeta = (cells[k] + 0.5) * h;
      const Sample &b = base.probes[k].back(), &t = top.probes[k].back();
      const double exact = loam::terzaghi_pressure(zeta, kCv * b.t);
      const double eb = std::fabs(b.p / kP0 - exact), et = std::fabs(t.p / kP0 - exact);
      std::printf(
          "  cell at z' = %.4f m from the drained face, t = %.3f s: exact %.1f Pa; drained base "
          "%.1f Pa (error %.4f p0), drained top %.1f Pa (error %.4f p0)\n",
          zeta, b.t, exact * kP0, b.p, eb, t.p, et);
      CHECK(eb <= 0.005);
      CHECK(et <= 0.005);
    }
    const double sb = base.summary["verify"]["final_settlement"];
    const double st = top.summary["verify"]["final_settlement"];
    std::printf("  settlement at 0.3 s: drained base %.4e m, drained top %.4e m (%+.2f %%)\n", sb,
                st, 100 * (sb / st - 1));
    CHECK(sb == Approx(st).epsilon(0.01));
  }
}

TEST_CASE("hydraulic: an impermeable top keeps the column undrained",
          "[two_phase][hydraulic][verification]") {
  // With the top sealed (w_n = v_n) no water can leave: the base pressure must average
  // Skempton's B p0 = 0.9982 p0 (within 5 %; it rings undamped about it) over 0.4 - 0.5 s,
  // when the free-top column has drained the base to 0.37 p0 (Terzaghi, T = 0.51; bound 0.5).
  const double end = 0.5;
  auto sealed =
      run_column("  - {type: fixed, face: x-}\n  - {type: impermeable, face: x+}\n", 0.0, end);
  auto open = run_column("  - {type: fixed, face: x-}\n", 0.0, end);
  const double ps = mean_p(sealed, 0.4, 0.5) / kP0, po = mean_p(open, 0.4, 0.5) / kP0;
  std::printf("impermeable top: base p/p0 averaged over 0.4-0.5 s %.4f (free top %.4f)\n", ps, po);
  CHECK(ps == Approx(0.9982).epsilon(0.05));
  CHECK(po < 0.5);
}

TEST_CASE("hydraulic: a sealed column loaded on its surface holds B p0 everywhere",
          "[two_phase][hydraulic][verification]") {
  // Fixed impermeable base, impermeable top, step load p0 on the top surface: no water can
  // leave, so once the undrained wave has decayed (drag) every particle holds Skempton's
  // B p0 = (K_w/n) / (K_w/n + M) p0 = 0.9981851 p0 and sigma'_xx = -(1 - B) p0. Target 1e-4 p0
  // at t = 1 s (measured 7e-5 at the top cell, 2e-6 elsewhere). With the load at the top
  // particle's centre (apply_at: particle) and linear hats, a quarter of it enters the cell
  // below: the top cell carries -7.5 kPa total, its skeleton goes into tension once the water
  // has evened out the pressure, and the column settles at 0.9938 B p0 (the 1.7 % / 9928 Pa
  // drift seen in review): a load-placement effect, which apply_at: surface removes.
  const double B = 5.5e9 / (5.5e9 + 1e7);
  auto r = run_column_probes(
      "  - {type: fixed, face: x-}\n  - {type: impermeable, face: x+}\n",
      {0.00625, 0.25625, 0.50625, 0.99375}, 1.0, "shape_function: gimp\n",
      "  - {type: traction, body: column, face: x+, traction: [-1.0e4], apply_at: surface}\n");
  for (const auto& s : r.probes) {
    const Sample& f = s.back();
    std::printf(
        "sealed column, surface load, particle at z = %.4f m, t = %.2f s: p = %.2f Pa (B p0 = "
        "%.2f), sigma'_xx = %.2f Pa (exact %.2f)\n",
        f.x, f.t, f.p, B * kP0, f.sxx, -(1 - B) * kP0);
    CHECK(std::fabs(f.p / kP0 - B) <= 1e-4);
    CHECK(std::fabs(f.sxx / kP0 + (1 - B)) <= 1e-4);
  }
}

TEST_CASE("hydraulic: prescribed pore pressure at the base drives steady upward seepage",
          "[two_phase][hydraulic][verification]") {
  // p = 5 kPa held on the fixed base (its cell stays full of soil) and p = 0 at the free top:
  // steady seepage with the linear profile p = 5000 (1 - z / H); the total stress stays the
  // load, -10 kPa, so sigma'_xx = -10000 + p. After T = 2.5 (transient < 1e-2 of its start)
  // the base and mid particles must show p and sigma'_xx within 2 % of that. The head form,
  // head = 5000 / 9810 m at the base (z = 0), must give the same run to 1e-6.
  const double end = 2.5 / kCv;
  const std::string fixed = "  - {type: fixed, face: x-}\n";
  // One run per form, each probing the base and the mid particle.
  auto pr = run_column_probes(
      fixed + "  - {type: prescribed_pore_pressure, face: x-, pressure: 5000}\n", {0.0, 0.5}, end);
  auto hd = run_column_probes(fixed + "  - {type: prescribed_pore_pressure, face: x-, head: " +
                                  std::to_string(5000.0 / 9810.0) + "}\n",
                              {0.0, 0.5}, end);
  for (size_t k = 0; k < 2; ++k) {
    const Sample &a = pr.probes[k].back(), &b = hd.probes[k].back();
    const double p_exact = 5000 * (1 - a.x);
    std::printf(
        "prescribed base pore pressure 5 kPa, particle at z = %.4f: p = %.1f Pa (exact "
        "%.1f), sigma'_xx = %.1f Pa (exact %.1f); head form %.1f Pa, %.1f Pa\n",
        a.x, a.p, p_exact, a.sxx, -1e4 + p_exact, b.p, b.sxx);
    CHECK(a.p == Approx(p_exact).epsilon(0.02));
    CHECK(a.sxx == Approx(-1e4 + p_exact).epsilon(0.02));
    CHECK(b.p == Approx(a.p).epsilon(1e-6));
    CHECK(b.sxx == Approx(a.sxx).epsilon(1e-6));
  }
}

TEST_CASE("hydraulic: a prescribed pore pressure follows its time function",
          "[two_phase][hydraulic][time_function]") {
  // time_function f scales the pressure, p f(t), or the head, gamma_w (head f(t) - z):
  //  - 10 kPa with f = 0.5 (constant) is the 5 kPa run, bitwise (10000 x 0.5 = 5000 exactly);
  //  - the head 2 x 5000/9810 m with f = 0.5 is the head run of 5000/9810 m, bitwise;
  //  - a ramp 0 -> 5 kPa over 0.3 s reaches the same steady seepage: base and mid particles
  //    within 2 % of p = 5000 (1 - z / H) (the previous test's reference and tolerance), and
  //    at t = 0.15 s the base particle's p is below the constant run's (the ramp is half way).
  // The bitwise pairs run to T = 0.5 (no steady state needed), the ramp to T = 2.5.
  const double end = 2.5 / kCv, short_end = 0.5 / kCv;
  const std::string fixed = "  - {type: fixed, face: x-}\n";
  const double x = 0.0;
  auto plain = run_column(
      fixed + "  - {type: prescribed_pore_pressure, face: x-, pressure: 5000}\n", x, short_end);
  auto half = run_column(fixed +
                             "  - {type: prescribed_pore_pressure, face: x-, pressure: 10000, "
                             "time_function: {type: constant, value: 0.5}}\n",
                         x, short_end);
  char head[256];
  std::snprintf(head, sizeof head, "%.17g", 5000.0 / 9810.0);
  char head2[256];
  std::snprintf(head2, sizeof head2, "%.17g", 2 * (5000.0 / 9810.0));
  auto hd = run_column(
      fixed + "  - {type: prescribed_pore_pressure, face: x-, head: " + head + "}\n", x, short_end);
  auto hd2 = run_column(fixed + "  - {type: prescribed_pore_pressure, face: x-, head: " + head2 +
                            ", time_function: {type: constant, value: 0.5}}\n",
                        x, short_end);
  std::printf(
      "prescribed pore pressure with f = 0.5: p %.17g (5 kPa run %.17g); head form %.17g "
      "(%.17g)\n",
      half.back().p, plain.back().p, hd2.back().p, hd.back().p);
  CHECK(half.back().p == plain.back().p);
  CHECK(half.back().sxx == plain.back().sxx);
  CHECK(hd2.back().p == hd.back().p);
  auto ramp = run_column(fixed +
                             "  - {type: prescribed_pore_pressure, face: x-, pressure: 5000, "
                             "time_function: {type: linear_ramp, duration: 0.3}}\n",
                         x, end);
  const Sample& a = ramp.back();
  const double p_exact = 5000 * (1 - a.x);
  const double early = at(ramp, 0.15).p, early_plain = at(plain, 0.15).p;
  std::printf(
      "ramped base pore pressure: at the end p = %.1f Pa (steady %.1f); at 0.15 s %.1f "
      "Pa (constant 5 kPa: %.1f)\n",
      a.p, p_exact, early, early_plain);
  CHECK(a.p == Approx(p_exact).epsilon(0.02));
  CHECK(early < 0.75 * early_plain);
}

TEST_CASE("hydraulic: conflicting or misplaced conditions are located errors",
          "[two_phase][hydraulic][cli]") {
  // Reference: docs/runs.md's error contract (Exit codes): FILE:LINE:COL: error: key.path: message,
  // all at once, exit 2, nothing written.
  loam_test::TempDir dir("hydraulic_bad");
  std::filesystem::create_directories(dir.path);
  const auto cfg = dir.path / "run.yaml";
  const std::string column =
      "grid: {origin: [0], extent: [1.0], cell_size: 0.1}\n"
      "bodies:\n"
      "  - name: column\n"
      "    generator: {type: box, min: [0], max: [1.0]}\n"
      "    material: {type: linear_elastic, E: 1.0e7, nu: 0.0, density: 2650}\n"
      "time: {end: 0.01}\n";
  // Two-phase: drained and impermeable on the same face.
  std::ofstream(cfg) << column
                     << "scheme: {type: two_phase_single_point, porosity: 0.4, drag: {type: "
                        "darcy, hydraulic_conductivity: 1.0e-3}}\n"
                        "boundaries:\n"
                        "  - {type: drained, face: x+}\n"
                        "  - {type: impermeable, face: x+}\n";
  auto r =
      loam_test::run_loam("run " + cfg.string() + " --quiet --out " + (dir.path / "out").string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(r.output.find(cfg.string() + ":10:") != std::string::npos);
  CHECK(r.output.find("error: boundaries.1.face: face x+ already has the hydraulic condition "
                      "'drained' (boundaries.0)") != std::string::npos);
  // Single phase: a hydraulic condition and a water-only fixity, both reported.
  std::ofstream(cfg) << column
                     << "boundaries:\n"
                        "  - {type: drained, face: x+}\n"
                        "  - {type: fixed, face: x-, phase: water}\n";
  r = loam_test::run_loam("run " + cfg.string() + " --quiet --out " + (dir.path / "out").string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("error: boundaries.0: 'drained' is a hydraulic condition on the pore "
                      "water: it needs a two-phase scheme") != std::string::npos);
  CHECK(r.output.find("error: boundaries.1.phase: phase: water needs a two-phase scheme") !=
        std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir.path / "out"));
}
