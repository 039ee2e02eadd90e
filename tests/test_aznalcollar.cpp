// Seed 002's Aznalcóllar dam (configs/seed002_aznalcollar.yaml,
// docs/aznalcollar.md): a rockfill dam raised downstream in four stages on a brittle,
// overconsolidated clay with a weaker bedding layer 14 m below the ground, tailings pressing on
// its upstream face and on the lagoon floor, two-phase single point, until it slides. The quick
// variant runs every stage on 4 m cells for 3 s each; the [full] test runs the config as shipped
// (2 m cells), compares the failure surface at 28 m with the observed one (Olalla & Cuéllar 2001:
// an almost flat surface about 14 m below the original ground) and prints the dam's first metres
// of displacement in the slide.
#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kGround = 40;  // original ground level y (m) in the config

/// The last frame of a run directory.
fs::path last_frame(const fs::path& dir) {
  fs::path last;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("particles_", 0) == 0 && e.path().extension() == ".h5" &&
        (last.empty() || n > last.filename().string()))
      last = e.path();
  }
  return last;
}

/// The frame written nearest to time t (from the XDMF index).
fs::path frame_at(const fs::path& dir, double t) {
  const std::string text = loam_test::slurp(dir / "particles.xdmf");
  const std::regex grid(R"re(Time Value="([^"]+)"[\s\S]*?([\w.]+\.h5):/position)re");
  fs::path best;
  double gap = 1e300;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), grid); it != std::sregex_iterator();
       ++it)
    if (const double g = std::fabs(std::stod((*it)[1].str()) - t); g < gap)
      gap = g, best = dir / (*it)[2].str();
  return best;
}

/// Count of non-finite values in every dataset of a frame that holds reals.
size_t non_finite_values(const fs::path& frame) {
  size_t bad = 0;
  for (const char* name :
       {"position", "velocity", "stress", "displacement", "plastic_strain_eq", "pore_pressure"}) {
    const auto v = loam_test::read_frame_doubles(frame, name);
    CHECK(!v.empty());
    for (double x : v) bad += !std::isfinite(x);
  }
  return bad;
}

/// The probe row at the end of a stage (the last row at or before end_time).
double at_stage_end(std::map<std::string, std::vector<double>>& probe, const std::string& column,
                    double end_time) {
  double value = std::nan("");
  for (size_t i = 0; i < probe["time"].size(); ++i)
    if (probe["time"][i] <= end_time * (1 + 1e-12)) value = probe[column][i];
  return value;
}

/// What every resolution must show: all stages ran, the dam joined stage by stage, no NaN, the
/// tailings pushed the dam downstream and the loading was undrained (pore pressure above
/// hydrostatic in the bedding under the toe). Prints the stages.
void check_stages(const nlohmann::json& s, const fs::path& dir, const char* variant) {
  REQUIRE(s["status"] == "ok");
  REQUIRE(s["stages"].size() == 6);
  for (const auto& st : s["stages"]) {
    std::printf(
        "aznalcollar %s: stage %-9s %-10s largest displacement %.3f m, moving at %.2e m/s\n",
        variant, st["name"].get<std::string>().c_str(), st["status"].get<std::string>().c_str(),
        st["max_displacement"].get<double>(), st.value("motion_speed", std::nan("")));
    CHECK(st["status"] != "not_run");
  }
  CHECK(s["stages"][0]["status"] == "static");  // the geostatic state is an equilibrium
  // The four raises joined: every particle generated is in the run at the end.
  CHECK(s["particles_created"].get<long>() > 0);
  CHECK(s["mass"]["balance"].get<double>() ==
        Approx(0).margin(1e-9 * s["mass"]["final"].get<double>()));
  const fs::path frame = last_frame(dir);
  REQUIRE(!frame.empty());
  const size_t bad = non_finite_values(frame);
  std::printf("aznalcollar %s: %zu non-finite values in the last frame %s\n", variant, bad,
              frame.filename().string().c_str());
  CHECK(bad == 0);
  // The crest probe waits (nan) until the first raise joins, then follows it downstream.
  auto crest = loam_test::read_csv_columns(dir / "probe_crest.csv");
  REQUIRE(crest.count("position_x"));
  CHECK(std::isnan(crest["position_x"].front()));
  const double end_28 = s["stages"][4]["end_time"].get<double>();
  const double crest_x = at_stage_end(crest, "position_x", end_28);
  std::printf("aznalcollar %s: crest moved %+.3f m along x by the end of the 28 m stage\n", variant,
              crest_x - 123.0);
  CHECK(crest_x - 123.0 > 0);
  // Undrained loading of the clay: pore pressure in the bedding under the toe above the
  // hydrostatic gamma_w z = 9810 x 14 Pa.
  auto band = loam_test::read_csv_columns(dir / "probe_bedding_under_toe.csv");
  REQUIRE(band.count("pore_pressure"));
  const double p = at_stage_end(band, "pore_pressure", end_28), hydrostatic = 9810 * 14.0;
  std::printf(
      "aznalcollar %s: pore pressure in the bedding under the toe %.0f kPa at the end of "
      "the 28 m stage, hydrostatic %.0f kPa\n",
      variant, p / 1e3, hydrostatic / 1e3);
  CHECK(p > hydrostatic + 1e5);
}

}  // namespace

TEST_CASE(
    "seed-002 Aznalcollar, quick variant (4 m cells, 3 s stages): every stage runs without NaN",
    "[aznalcollar][seed002]") {
  loam_test::TempDir d("aznalcollar_quick");
  std::string short_stages = " --set grid.cell_size=4 --set stages.5.duration=3";
  for (int k = 0; k < 5; ++k) short_stages += " --set stages." + std::to_string(k) + ".max_time=3";
  const auto s =
      loam_test::run_scene("seed002_aznalcollar.yaml", d.path, "--threads 1" + short_stages);
  check_stages(s, d.path, "quick");
}

TEST_CASE(
    "seed-002 Aznalcollar as shipped: a flat slip surface in the bedding 14 m down, the dam slides",
    "[aznalcollar][seed002][full]") {
  loam_test::TempDir d("aznalcollar_full");
  const auto s = loam_test::run_scene("seed002_aznalcollar.yaml", d.path, "--threads 2");
  check_stages(s, d.path, "full");
  std::printf("aznalcollar full: %ld particles, %ld steps, %.0f s wall, %.2f M particle-steps/s\n",
              s["particles"].get<long>(), s["steps"].get<long>(), s["wall_seconds"].get<double>(),
              s["particle_steps_per_second"].get<double>() / 1e6);
  // The failure surface at the end of the 28 m stage (before the tailings liquefy): per 4 m
  // column over the middle of the dam's footprint, from 24 m downstream of the upstream toe to
  // 14 m upstream of the final toe (x 124-188 m; near the upstream toe the active wedge shears
  // the top metres, near the final toe the band rises to the surface), the depth of the foundation
  // point with the largest equivalent plastic deviatoric strain. Observed (Olalla & Cuellar 2001):
  // almost flat, about 14 m below the original ground; the model's bedding layer spans 12-16 m.
  // Target: every column's band within 11.5-16.5 m (the layer and half a cell).
  const double end_28 = s["stages"][4]["end_time"].get<double>();
  const fs::path frame = frame_at(d.path, end_28);
  REQUIRE(!frame.empty());
  const auto x = loam_test::read_frame_doubles(frame, "position");
  const auto eps = loam_test::read_frame_doubles(frame, "plastic_strain_eq");
  const size_t n = eps.size();
  REQUIRE(x.size() == 3 * n);
  double shallowest = 1e9, deepest = -1e9;
  for (double a = 124; a < 188; a += 4) {
    size_t best = n;
    for (size_t i = 0; i < n; ++i)
      if (x[3 * i] >= a && x[3 * i] < a + 4 && x[3 * i + 1] < kGround &&
          (best == n || eps[i] > eps[best]))
        best = i;
    REQUIRE(best < n);
    const double depth = kGround - x[3 * best + 1];
    std::printf(
        "aznalcollar full: end of the 28 m stage, column x %.0f-%.0f m: band %.1f m "
        "below ground (plastic_strain_eq %.3f)\n",
        a, a + 4, depth, eps[best]);
    shallowest = std::min(shallowest, depth), deepest = std::max(deepest, depth);
    // Softening under way: the strains soften over 0.15 l_c / h = 0.3 on the 2 m cells.
    CHECK(eps[best] > 0.1);
  }
  std::printf(
      "aznalcollar full: slip surface %.1f-%.1f m below ground under the dam (observed: "
      "about 14 m, almost flat)\n",
      shallowest, deepest);
  CHECK(shallowest >= 11.5);
  CHECK(deepest <= 16.5);
  // The slide: the dam's first metres of displacement in the last stage (undamped, the
  // tailings liquefied). Measured 2026-12-04 with the back-calculated bedding: about 10 m in 8 s,
  // then at rest (the field: about 60 m; the model's tailings push with a constant force).
  auto crest = loam_test::read_csv_columns(d.path / "probe_crest.csv");
  const double t0 = s["stages"][5]["start_time"].get<double>();
  const double x0 = at_stage_end(crest, "position_x", t0);
  double moved = 0;
  for (double t = 1; t <= 20; t += 1) {
    const double u = at_stage_end(crest, "position_x", t0 + t) - x0;
    std::printf("aznalcollar full: slide t = %2.0f s: crest displacement %.2f m\n", t, u);
    moved = u;
  }
  CHECK(moved > 1.0);
}
