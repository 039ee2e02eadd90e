// Sources and sinks (framework/source.hpp, framework/sink.hpp; plugins/sources/inflow.cpp,
// plugins/sinks/region.cpp, plugins/sinks/plane.cpp). Water flows into a channel through an
// inlet on its left face and leaves through an outlet box at its right end:
//   - mass balance: mass now + removed - created - initial = 0 to round-off, every step;
//   - steady outflow rate = rho v A (reference: mass conservation of a plug flow at v through
//     the cross-section A, per unit thickness in 2D) within 1 %;
//   - ids unique over the run; ParaView frames whose particle count changes.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>

#include "cli.hpp"
#include "sim_helpers.hpp"

namespace fs = std::filesystem;
using namespace loam_test;

namespace {

constexpr double kRho = 1000, kV = 1.0, kH = 0.2;  // water, inflow speed, channel height

/// A 1 m x 0.2 m channel (cell 0.02 m, slip walls), no gravity; `water` enters through the
/// x- face at v = 1 m/s and leaves through the outlet box x >= 0.8 m.
std::string channel(const std::string& extra_sources = "", const std::string& sinks = "") {
  return std::string(
             "grid: {origin: [0, 0], extent: [1.0, 0.2], cell_size: 0.02}\n"
             "shape_function: gimp\n"
             "gravity: [0, 0]\n"
             "bodies:\n"
             "  - name: water\n"
             "    particles_per_cell: 2\n"
             "    material: {type: newtonian_fluid, bulk_modulus: 2.0e5, viscosity: 1.0e-3, "
             "density: 1000}\n"
             "boundaries:\n"
             "  - {type: slip, face: y-}\n"
             "  - {type: slip, face: y+}\n"
             "sources:\n"
             "  - {type: inflow, body: water, face: x-, min: [0, 0], max: [0, 0.2], velocity: [1, "
             "0]}\n") +
         extra_sources + "sinks:\n" +
         (sinks.empty() ? "  - {type: region, min: [0.8, 0], max: [1.0, 0.2]}\n" : sinks) +
         "time: {end: 2.0, cfl: 0.5}\n"
         "output: {every_time: 0.25, fields: [velocity, stress]}\n";
}

/// The channel runs on one thread (small runs crawl on two threads of a loaded 2-core host).
CliResult run_text(const fs::path& dir, const std::string& yaml, const std::string& args = "") {
  return run_yaml(dir, yaml, "--threads 1 " + args);
}

/// Least-squares slope of y against x over the samples with x in [x0, x1].
double slope(const std::vector<double>& x, const std::vector<double>& y, double x0, double x1) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size(); ++i)
    if (x[i] >= x0 && x[i] <= x1) {
      n += 1, sx += x[i], sy += y[i], sxx += x[i] * x[i], sxy += x[i] * y[i];
    }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

}  // namespace

TEST_CASE("inflow -> channel -> outlet: mass balance, outflow rho v A, unique ids, frames",
          "[sources][verification]") {
  TempDir dir("channel");
  auto r = run_text(dir.path, channel(), "--set output.history_every=1");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const fs::path out = dir.path / "out";
  std::ifstream js(out / "summary.json");
  const auto s = nlohmann::json::parse(js);
  const auto& m = s["mass"];
  const double created = m["created"], removed = m["removed"], balance = m["balance"];
  std::printf(
      "channel: %zu particles created, %zu removed, mass created %.6g kg/m, removed %.6g, "
      "final %.6g, balance %.3g kg/m (tolerance 1e-9 of the created mass)\n",
      s["particles_created"].get<size_t>(), s["particles_removed"].get<size_t>(), created, removed,
      m["final"].get<double>(), balance);
  CHECK(s["particles_created"].get<size_t>() > 1000);
  CHECK(s["particles_removed"].get<size_t>() > 1000);
  CHECK(m["initial"].get<double>() == 0.0);
  CHECK(std::fabs(balance) <= 1e-9 * created);

  // Every sample of history.csv balances too, and the outflow rate in the steady state (the
  // front reaches the outlet at t = 0.8 s; the last 1 s) is rho v A.
  const auto h = read_csv_columns(out / "history.csv");
  REQUIRE(h.count("mass_removed") == 1);
  const auto& t = h.at("time");
  const double rate = slope(t, h.at("mass_removed"), 1.0, 2.0);
  const double inflow = slope(t, h.at("mass_created"), 1.0, 2.0);
  const double expected = kRho * kV * kH;
  std::printf(
      "outflow rate %.5g kg/s/m, inflow rate %.5g, rho v A = %.5g: errors %+.3f %%, %+.3f %% "
      "(tolerance 1 %%)\n",
      rate, inflow, expected, 100 * (rate / expected - 1), 100 * (inflow / expected - 1));
  CHECK(std::fabs(rate / expected - 1) < 0.01);
  CHECK(std::fabs(inflow / expected - 1) < 0.01);
  // In the steady state the channel holds a constant amount (the count varies by a layer).
  const auto& n = h.at("particles");
  double nmin = 1e300, nmax = 0;
  for (size_t i = 0; i < t.size(); ++i)
    if (t[i] >= 1.0) nmin = std::min(nmin, n[i]), nmax = std::max(nmax, n[i]);
  std::printf("particles in the channel for t >= 1 s: %.0f to %.0f (one layer: 20)\n", nmin, nmax);
  CHECK(nmax - nmin <= 2 * 20);

  // Ids: unique in every frame, never reused (a removed id never comes back), and new ones grow.
  std::set<int> seen_removed, previous;
  std::vector<size_t> counts;
  for (int k = 0;; ++k) {
    char name[64];
    std::snprintf(name, sizeof name, "particles_%06d.h5", k);
    if (!fs::exists(out / name)) break;
    const auto ids = read_frame_ids(out / name);
    const std::set<int> now(ids.begin(), ids.end());
    CHECK(now.size() == ids.size());
    for (int id : previous)
      if (!now.count(id)) seen_removed.insert(id);
    for (int id : now) CHECK(seen_removed.count(id) == 0);
    previous = now;
    counts.push_back(ids.size());
  }
  // ParaView: the index names every frame with its own count.
  const std::string x = slurp(out / "particles.xdmf");
  size_t listed = 0;
  for (size_t k = 0; k < counts.size(); ++k)
    listed += x.find("NumberOfElements=\"" + std::to_string(counts[k]) + "\"") != std::string::npos;
  std::printf("%zu frames, particle counts %zu .. %zu, ids removed and never reused: %zu\n",
              counts.size(), counts.front(), counts.back(), seen_removed.size());
  CHECK(counts.size() == 9);
  CHECK(counts.front() == 20);  // frame 0: the inlet, one layer deep, filled at t = 0
  CHECK(listed == counts.size());
  CHECK(seen_removed.size() > 1000);
}

TEST_CASE("a plane sink keeps a water level, a source window stops the inflow", "[sources]") {
  // The inflow runs for 0.5 s only: created mass rho v A 0.5 s (to one layer), and the plane
  // x > 0.6 m removes everything that passes it.
  TempDir dir("channel_plane");
  std::string yaml = channel("", "  - {type: plane, point: [0.6, 0], normal: [1, 0]}\n");
  yaml = std::regex_replace(yaml, std::regex("velocity: \\[1, 0\\]\\}"),
                            "velocity: [1, 0], end: 0.5}");
  auto r = run_text(dir.path, yaml);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  std::ifstream js(dir.path / "out/summary.json");
  const auto s = nlohmann::json::parse(js);
  const double created = s["mass"]["created"], expected = kRho * kV * kH * 0.5;
  const double layer = kRho * kH * 0.01;  // one layer of the inlet lattice
  std::printf(
      "window 0.5 s: created %.5g kg/m, rho v A T = %.5g (one layer %.3g), left at the end "
      "%.3g kg/m, balance %.3g\n",
      created, expected, layer, s["mass"]["final"].get<double>(),
      s["mass"]["balance"].get<double>());
  // The fill itself is one inlet depth (one layer), then one layer per 0.01 m of travel.
  CHECK(std::fabs(created - expected) <= 1.5 * layer);
  CHECK(s["mass"]["final"].get<double>() == 0.0);  // all water passed the plane by t = 2 s
  CHECK(std::fabs(s["mass"]["balance"].get<double>()) <= 1e-9 * created);
}

TEST_CASE("open_faces removes what leaves through the open end, without it that is exit 3",
          "[sources]") {
  // The channel's x+ face is open (no condition holds it): the water leaves the grid there.
  TempDir with("channel_open"), without("channel_open_none");
  auto r =
      run_text(with.path, channel("", "  - {type: open_faces}\n"), "--set output.history_every=1");
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  std::ifstream js(with.path / "out/summary.json");
  const auto s = nlohmann::json::parse(js);
  const auto h = read_csv_columns(with.path / "out/history.csv");
  const double rate = slope(h.at("time"), h.at("mass_removed"), 1.2, 2.0);
  std::printf(
      "open_faces: removed %zu particles, outflow rate %.5g kg/s/m (rho v A = %.5g, %+.3f "
      "%%, tolerance 1 %%), balance %.3g\n",
      s["particles_removed"].get<size_t>(), rate, kRho * kV * kH,
      100 * (rate / (kRho * kV * kH) - 1), s["mass"]["balance"].get<double>());
  CHECK(s["particles_removed"].get<size_t>() > 1000);
  CHECK(std::fabs(rate / (kRho * kV * kH) - 1) < 0.01);
  CHECK(std::fabs(s["mass"]["balance"].get<double>()) <= 1e-9 * s["mass"]["created"].get<double>());
  // Without a sink the first particle through the open face stops the run.
  std::string none = channel();
  none = none.substr(0, none.find("sinks:")) + none.substr(none.find("time:"));
  auto r2 = run_text(without.path, none);
  std::printf("without a sink: exit %d: %s", r2.exit_code, r2.output.c_str());
  CHECK(r2.exit_code == 3);
  CHECK(r2.output.find("left the grid") != std::string::npos);
}

TEST_CASE("sources and sinks: located errors for bad input, exit 2, nothing written",
          "[sources][bad_config]") {
  struct Case {
    std::string what, yaml, expect;
  };
  auto with = [](const std::string& a, const std::string& b) {
    std::string s = channel();
    const size_t k = s.find(a);
    REQUIRE(k != std::string::npos);
    return s.replace(k, a.size(), b);
  };
  const std::string inflow =
      "{type: inflow, body: water, face: x-, min: [0, 0], max: [0, 0.2], velocity: [1, 0]}";
  const std::vector<Case> cases = {
      {"zero velocity",
       with(inflow,
            "{type: inflow, body: water, face: x-, min: [0, 0], max: [0, "
            "0.2], velocity: [0, 0]}"),
       "error: sources.0.velocity: zero velocity: no inflow"},
      {"velocity out of the grid", with("velocity: [1, 0]", "velocity: [-1, 0]"),
       "error: sources.0.velocity: the velocity does not point into the grid through face x-"},
      {"source outside the grid",
       with(inflow,
            "{type: inflow, body: water, min: [-0.1, 0], max: [0.1, 0.2], velocity: [1, 0]}"),
       "error: sources.0: the source region [-0.1, 0] to [0.1, 0.2] is outside the grid"},
      {"unknown body", with("body: water, face", "body: wter, face"),
       "error: sources.0.body: unknown body 'wter'; bodies are: water"},
      {"overlapping source and sink",
       with("{type: region, min: [0.8, 0]", "{type: region, min: [0.0, 0]"),
       "error: sinks.0: the sink overlaps the region of sources.0"},
      {"unknown set of a sink",
       with("{type: region, min: [0.8, 0], max: [1.0, 0.2]}",
            "{type: region, min: [0.8, 0], max: [1.0, 0.2], set: wet}"),
       "error: sinks.0.set: unknown particle set 'wet'"},
      {"a load on a body that starts empty",
       with("sources:",
            "loads:\n  - {type: traction, body: water, face: y+, traction: [0, 1]}\nsources:"),
       "error: loads.0.body: body 'water' has no particles at t = 0 (no generator)"},
      {"a reservoir's time function without a level rate",
       with(inflow,
            "{type: reservoir, body: water, min: [0, 0], max: [0.2, 0.2], refill: x-, "
            "time_function: {type: constant, value: 2}}"),
       "error: sources.0.time_function: the time function scales level_rate: give a "
       "level_rate > 0"},
      {"an unknown time function of an inflow",
       with("velocity: [1, 0]}", "velocity: [1, 0], time_function: {type: ramp}}"),
       "unknown time_function 'ramp'"},
  };
  for (const auto& c : cases) {
    TempDir dir("sources_bad");
    auto r = run_text(dir.path, c.yaml);
    std::printf("%s: exit %d: %s", c.what.c_str(), r.exit_code, r.output.c_str());
    CHECK(r.exit_code == 2);
    CHECK(r.output.find(c.expect) != std::string::npos);
    CHECK_FALSE(fs::exists(dir.path / "out"));
  }
}

TEST_CASE("particles added by a source get every plugin's initial state", "[sources][unit]") {
  // gimp half-widths = spacing / 2, F = identity, the two-phase porosity n0 and solid mass
  // (1 - n0) rho_s V, initial position for the displacement: the same as generated particles.
  auto sim = make_simulation<2>(
      "grid: {origin: [0, 0], extent: [0.4, 0.2], cell_size: 0.02}\n"
      "shape_function: {type: gimp, domain_update: stretch}\n"
      "scheme: {type: two_phase_single_point, porosity: 0.4, drag: {type: darcy, "
      "hydraulic_conductivity: 1e-3}}\n"
      "gravity: [0, 0]\n"
      "bodies:\n"
      "  - {name: soil, generator: {type: box, min: [0.2, 0], max: [0.4, 0.2]}, material: {type: "
      "linear_elastic, E: 1e7, nu: 0.3, density: 2650}}\n"
      "  - {name: more, material: {type: linear_elastic, E: 1e7, nu: 0.3, density: 2650}}\n"
      "boundaries: [{type: slip, face: y-}]\n"
      "sources:\n"
      "  - {type: inflow, body: more, min: [0.0, 0], max: [0.02, 0.2], velocity: [0.1, 0]}\n"
      "time: {end: 1}\n");
  auto& P = sim->sets[0].particles;
  const size_t n0 = 400;         // generated: 20 x 20 at spacing 0.01 m
  REQUIRE(P.size() == n0 + 40);  // filled at t = 0: the region's 2 x 20 lattice sites
  advance(*sim, 1);
  REQUIRE(P.size() == n0 + 40);  // no new layer yet (0.1 m/s for one step)
  const int F = P.find("deformation_gradient"), lp = P.find("gimp_half_width"),
            lp0 = P.find("gimp_half_width0"), n = P.find("porosity"), w = P.find("water_velocity");
  size_t checked = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    if (P.body[i] != 1) continue;
    ++checked;
    CHECK(P.id[i] >= n0);  // fresh ids after the generated ones
    CHECK(P.col(lp, 0)[i] == Approx(0.005));
    CHECK(P.col(lp0, 1)[i] == Approx(0.005));
    CHECK(std::fabs(P.col(F, 0)[i] - 1) < 1e-6);  // identity, then one small step
    CHECK(std::fabs(P.col(F, 1)[i]) < 1e-6);
    CHECK(P.col(n)[i] == Approx(0.4).margin(1e-6));
    CHECK(P.col(P.mass)[i] == Approx(0.6 * 2650 * 1e-4).epsilon(1e-12));
    CHECK(P.col(w, 0)[i] == Approx(0.1).epsilon(1e-3));
  }
  std::printf("source particles checked: %zu (gimp lp, F, porosity, solid mass, water velocity)\n",
              checked);
  CHECK(checked == 40);
}

TEST_CASE("an inflow's time function scales its velocity and the mass it creates", "[sources]") {
  // The same 0.5 s window with the velocity ramped from 0 to 1 m/s over 0.4 s
  // (linear_ramp): the layers advance by v int_0^0.5 f dt = 1 x (0.5 - 0.2) = 0.3 m, so the
  // created mass is rho A (0.3 m) plus the fill (one layer), to one layer; the inlet particles
  // move at v f(t).
  TempDir dir("channel_ramp");
  std::string yaml = channel("", "  - {type: plane, point: [0.6, 0], normal: [1, 0]}\n");
  yaml = std::regex_replace(
      yaml, std::regex("velocity: \\[1, 0\\]\\}"),
      "velocity: [1, 0], end: 0.5, time_function: {type: linear_ramp, duration: 0.4}}");
  auto r = run_text(dir.path, yaml);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  std::ifstream js(dir.path / "out/summary.json");
  const auto s = nlohmann::json::parse(js);
  const double created = s["mass"]["created"], expected = kRho * kH * 0.3;
  const double layer = kRho * kH * 0.01;
  std::printf(
      "ramped inflow, window 0.5 s: created %.5g kg/m, rho A v int f dt = %.5g (one "
      "layer %.3g), balance %.3g\n",
      created, expected, layer, s["mass"]["balance"].get<double>());
  CHECK(std::fabs(created - expected) <= 1.5 * layer);
  CHECK(std::fabs(s["mass"]["balance"].get<double>()) <= 1e-9 * created);
}
