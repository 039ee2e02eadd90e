// Reactions of the mechanical boundary conditions (framework/reactions.hpp): the force each
// applies on the model, sum m (a_after - a_before) over its nodes, per phase, in history.csv
// and summary.json; node probes at a position (node_near).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "cli.hpp"
#include "sim_helpers.hpp"

namespace {

/// The column of configs/elastic_column_2d.yaml (1 x 10 m, rho 2000, E 1 GPa, fixed base, slip
/// sides, local damping 0.3) started from its geostatic stress (K0 = nu / (1 - nu)), with
/// `shape`; its weight per metre W = rho g H = 196 200 N/m.
std::string column_at_rest(const std::string& shape) {
  return R"(
grid: {origin: [0, 0], extent: [1.0, 10.5], cell_size: 0.25}
gravity: [0, -9.81]
shape_function: )" +
         shape + R"(
bodies:
  - name: column
    generator: {type: box, min: [0, 0], max: [1.0, 10]}
    particles_per_cell: 2
    material: {type: linear_elastic, E: 1.0e9, nu: 0.3, density: 2000}
    stress: {type: linear_profile, value: [0, 0, 0, 0], gradient: [8408.571, 19620, 8408.571, 0], axis: 1, origin: 10}
boundaries:
  - {type: fixed, face: y-}
  - {type: slip, face: x-}
  - {type: slip, face: x+}
damping: {type: local, alpha: 0.3}
time: {end: 0.5}
)";
}

/// The mean of column `slot`'s force component c over the steps [from, to) of a simulation.
template <int D>
double mean_reaction(loam::Simulation<D>& sim, size_t slot, int c, int from, int to) {
  loam_test::advance(sim, from);
  double sum = 0;
  for (int k = from; k < to; ++k) {
    loam_test::advance(sim, 1);
    sum += sim.reactions.force(slot)[c];
  }
  return sum / (to - from);
}

}  // namespace

TEST_CASE("reactions: a fixed base carries the weight of a column at rest, every shape function",
          "[reactions][boundaries]") {
  // Reference: statics, the base's reaction equals the column's weight W = rho g H b = 196 200
  // N/m (2D, per metre); the slip walls' horizontal reactions balance each other (the K0
  // thrust, equal and opposite). Tolerance 0.1 % of W for the mean over steps 400-600 (the
  // geostatic start is within the discretisation of the discrete equilibrium, damped).
  const double W = 2000 * 9.81 * 10;
  for (const char* shape : {"linear", "gimp", "bspline2", "cpdi"}) {
    auto sim = loam_test::make_simulation<2>(column_at_rest(shape));
    REQUIRE(sim->reactions.names() == std::vector<std::string>{"fixed_y-", "slip_x-", "slip_x+"});
    const double base = mean_reaction(*sim, 0, 1, 400, 600);
    const double left = sim->reactions.force(1)[0], right = sim->reactions.force(2)[0];
    std::printf(
        "column at rest (%s): base reaction %.2f N/m against W = %.0f (%+.4f %%); walls %.1f and "
        "%.1f N/m\n",
        shape, base, W, 100 * (base / W - 1), left, right);
    CHECK(std::fabs(base / W - 1) <= 1e-3);
    CHECK(left > 0);  // the left wall pushes +x, the right one -x
    CHECK(right < 0);
    CHECK(std::fabs(left + right) <= 1e-3 * left);
  }
}

TEST_CASE("reactions: the base of a two-phase column carries soil and water, both schemes",
          "[reactions][boundaries][two_phase]") {
  // Reference: statics, the fixed (impermeable) base of a saturated 1 m column at rest carries
  // its whole weight per unit area, ((1 - n) rho_s + n rho_w) g H = 19 522.9 N/m^2 for n = 0.4,
  // rho_s = 2650, rho_w = 1000 (configs/hydrostatic_column.yaml, single point); the double-point
  // column of configs/hydrostatic_double_point.yaml adds its free water above the soil. The sum
  // of the phases' reactions, mean over steps 200-400, within 0.1 %.
  // Each also with both phases under local damping (`liquid: true`): the damping's force on a
  // held component is no reaction, for the water as for the solid.
  for (const std::string damping : {"", "damping: {type: local, alpha: 0.7, liquid: true}\n"}) {
    INFO(damping);
    const std::string yaml = loam_test::slurp(std::filesystem::path(LOAM_SOURCE_DIR) / "configs" /
                                              "hydrostatic_column.yaml") +
                             damping;
    auto sim = loam_test::make_simulation<1>(yaml);
    const double solid = mean_reaction(*sim, 0, 0, 200, 400);
    const double water = sim->reactions.force(0)[1];
    const double W = (0.6 * 2650 + 0.4 * 1000) * 9.81 * 1.0;
    std::printf(
        "single point column%s: base reaction solid %.2f + water %.2f (last step) = %.2f N/m^2 "
        "against %.2f\n",
        damping.empty() ? "" : " (damped)", solid, water, solid + water, W);
    // The water's share is measured in the same steps: redo the mean of the sum.
    auto again = loam_test::make_simulation<1>(yaml);
    loam_test::advance(*again, 200);
    double sum = 0;
    for (int k = 0; k < 200; ++k) {
      loam_test::advance(*again, 1);
      sum += again->reactions.force(0)[0] + again->reactions.force(0)[1];
    }
    std::printf("single point column%s: mean total base reaction %.2f N/m^2 (%+.4f %%)\n",
                damping.empty() ? "" : " (damped)", sum / 200, 100 * (sum / 200 / W - 1));
    CHECK(std::fabs(sum / 200 / W - 1) <= 1e-3);
  }
  for (const std::string damping : {"", "damping: {type: local, alpha: 0.7, liquid: true}\n"}) {
    INFO(damping);
    const std::string yaml = loam_test::slurp(std::filesystem::path(LOAM_SOURCE_DIR) / "configs" /
                                              "hydrostatic_double_point.yaml") +
                             damping;
    auto sim = loam_test::make_simulation<1>(yaml);
    double W = 0;
    for (const auto& set : sim->sets)
      for (size_t i = 0; i < set.size(); ++i) W += set.particles.col(set.particles.mass)[i] * 9.81;
    loam_test::advance(*sim, 200);
    double sum = 0;
    for (int k = 0; k < 200; ++k) {
      loam_test::advance(*sim, 1);
      sum += sim->reactions.force(0)[0] + sim->reactions.force(0)[1];
    }
    std::printf(
        "double point column%s: mean total base reaction %.2f N/m^2 against %.2f (%+.4f %%)\n",
        damping.empty() ? "" : " (damped)", sum / 200, W, 100 * (sum / 200 / W - 1));
    CHECK(std::fabs(sum / 200 / W - 1) <= 1e-3);
  }
}

TEST_CASE("reactions: history.csv and summary.json carry each condition's force by its name",
          "[reactions][cli]") {
  // The column of the first test through `loam run`: the base named `base`, the walls by
  // default; the history columns reaction_base_x, reaction_base_y, reaction_slip_x-_x, ...;
  // summary.json's reactions.base.force equals the last history row (history_every 1), and its
  // min and max are those of the rows after the start. A node probe at a position samples the
  // nearest node.
  loam_test::TempDir dir("reactions_cli");
  std::string yaml = column_at_rest("gimp");
  const std::string base = "  - {type: fixed, face: y-}";
  yaml.replace(yaml.find(base), base.size(), "  - {type: fixed, face: y-, name: base}");
  yaml.replace(yaml.find("time: {end: 0.5}"), 16,
               "time: {end: 0.05}\noutput: {every_time: 1, history_every: 1, history_digits: 17}\n"
               "probes: [{name: top, node_near: [0.49, 10.1], fields: [velocity, mass]},\n"
               "         {name: node, node: [2, 40], fields: [velocity, mass]}]");
  const auto r = loam_test::run_yaml(dir.path, yaml);
  REQUIRE(r.exit_code == 0);
  const auto h = loam_test::read_csv_columns(dir.path / "out" / "history.csv");
  for (const char* c : {"reaction_base_x", "reaction_base_y", "reaction_slip_x-_x",
                        "reaction_slip_x-_y", "reaction_slip_x+_x"})
    CHECK(h.count(c) == 1);
  const auto s = nlohmann::json::parse(std::ifstream(dir.path / "out" / "summary.json"));
  const auto& y = h.at("reaction_base_y");
  const double last = s["reactions"]["base"]["force"][1];
  const double lo = s["reactions"]["base"]["min"][1], hi = s["reactions"]["base"]["max"][1];
  double rows_lo = 1e300, rows_hi = -1e300;
  for (size_t k = 1; k < y.size(); ++k)  // row 0: the start, before any step
    rows_lo = std::min(rows_lo, y[k]), rows_hi = std::max(rows_hi, y[k]);
  std::printf("named base: last %.3f N/m, min %.3f, max %.3f over %zu rows\n", last, lo, hi,
              y.size());
  CHECK(last == Approx(y.back()).epsilon(1e-14));
  CHECK(lo == Approx(rows_lo).epsilon(1e-14));
  CHECK(hi == Approx(rows_hi).epsilon(1e-14));
  // node_near [0.49, 10.1] is node (2, 40) of the 0.25 m grid: its rows are the node probe's.
  const auto p = loam_test::read_csv_columns(dir.path / "out" / "probe_top.csv");
  const auto q = loam_test::read_csv_columns(dir.path / "out" / "probe_node.csv");
  REQUIRE(p.count("mass") == 1);
  CHECK(p.at("mass") == q.at("mass"));
  CHECK(p.at("velocity_y") == q.at("velocity_y"));
  CHECK(p.at("mass").back() > 0);
}

TEST_CASE("reactions: a name given twice and a node_near outside the grid are located errors",
          "[reactions][cli]") {
  loam_test::TempDir dir("reactions_bad");
  std::string yaml = column_at_rest("linear");
  yaml.replace(yaml.find("  - {type: slip, face: x-}"), 26,
               "  - {type: slip, face: x-, name: wall}");
  yaml.replace(yaml.find("  - {type: slip, face: x+}"), 26,
               "  - {type: slip, face: x+, name: wall}");
  yaml += "probes: [{name: far, node_near: [5, 5], fields: [velocity]}]\n";
  const auto r = loam_test::run_yaml(dir.path, yaml);
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("boundaries.2.name: another condition of this list reports its reaction "
                      "as 'wall'") != std::string::npos);
  CHECK(r.output.find("probes.0.node_near: the point is outside the grid") != std::string::npos);
  CHECK(!std::filesystem::exists(dir.path / "out"));
}
