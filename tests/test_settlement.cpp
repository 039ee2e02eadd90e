// The settlement reference (plugins/references/settlement.cpp) on hand-made states: particle
// volumes, stresses and pore pressures set directly, metrics against values computed by hand. The
// seed 001 MCC regression (tests/test_seed001_mcc.cpp) uses it through the command line.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "sim_helpers.hpp"

namespace {

/// A column 1 m high (0.1 m wide in 2D) with particles from two bodies: `column` and, above it,
/// `cap`, which the reference must ignore.
template <int D>
std::string scene() {
  auto vec = [](double lateral, double vertical) {
    std::string s = "[";
    for (int d = 0; d < D; ++d)
      s += (d ? ", " : "") + std::to_string(d == D - 1 ? vertical : lateral);
    return s + "]";
  };
  return "grid: {extent: " + vec(0.2, 1.5) +
         ", cell_size: 0.1}\n"
         "bodies:\n"
         "  - name: cap\n    generator: {type: box, min: " +
         vec(0, 1.0) + ", max: " + vec(0.1, 1.2) +
         "}\n    material: {type: linear_elastic, E: 1.0e7, nu: 0, density: 2000}\n"
         "  - name: column\n    generator: {type: box, min: " +
         vec(0, 0) + ", max: " + vec(0.1, 1.0) +
         "}\n    material: {type: linear_elastic, E: 1.0e7, nu: 0, density: 2000}\n"
         "time: {end: 1}\n";
}

template <int D>
void check_settlement() {
  // Hand values: every column particle's volume times 0.9 -> height 0.9 m, settlement 0.1 m;
  // expected 0.08 -> error +0.25; paper 0.125 -> -0.2. Vertical effective stress -2e4 and -4e4
  // Pa on alternate particles of equal volume -> mean 3e4 Pa (compression +); the lateral
  // components -1e6 must not count. One pore pressure of -500 Pa and the cap's 1e6 Pa (another
  // body) -> max |p| / load = 500 / 1e4 = 0.05.
  auto sim = loam_test::make_simulation<D>(scene<D>());
  auto& P = sim->sets[0].particles;
  const int pore = P.request({"pore_pressure", 1, "Pa", "excess pore pressure", {}});
  auto ref = loam_test::make_reference<D>(*sim,
                                          "{type: settlement, body: column, load: 1.0e4, "
                                          "expected_settlement: 0.08, paper_settlement: 0.125}");
  constexpr int NS = loam::Particles<D>::NS;
  size_t k = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    if (sim->bodies[size_t(P.body[i])].name != "column") {
      P.col(P.volume)[i] *= 0.5;  // the cap must not count
      P.col(pore)[i] = 1e6;
      continue;
    }
    P.col(P.volume)[i] *= 0.9;
    for (int c = 0; c < NS; ++c) P.col(P.stress, c)[i] = c < 3 ? -1e6 : 0.0;
    P.col(P.stress, D - 1)[i] = (k++ % 2) ? -2e4 : -4e4;
    P.col(pore)[i] = 0;
  }
  REQUIRE(k % 2 == 0);
  for (size_t i = 0; i < P.size(); ++i)
    if (sim->bodies[size_t(P.body[i])].name == "column") {
      P.col(pore)[i] = -500;
      break;
    }
  auto m = ref->metrics(*sim);
  std::printf(
      "settlement reference %dD: height %.15f, settlement %.15f, error %.15f, vs paper %.15f, "
      "vertical stress %.6f Pa, residual %.15f\n",
      D, m["final_height"], m["final_settlement"], m["settlement_error"], m["settlement_vs_paper"],
      m["vertical_stress"], m["residual_pore_pressure"]);
  CHECK(m["final_height"] == Approx(0.9).epsilon(1e-12));
  CHECK(m["final_settlement"] == Approx(0.1).epsilon(1e-11));
  CHECK(m["expected_settlement"] == 0.08);
  CHECK(m["settlement_error"] == Approx(0.25).epsilon(1e-10));
  CHECK(m["paper_settlement"] == 0.125);
  CHECK(m["settlement_vs_paper"] == Approx(-0.2).epsilon(1e-10));
  CHECK(m["vertical_stress"] == Approx(3e4).epsilon(1e-12));
  CHECK(m["residual_pore_pressure"] == Approx(0.05).epsilon(1e-12));
}

}  // namespace

TEST_CASE("settlement reference: height, settlement, stress and residual by hand, 1D",
          "[reference][unit]") {
  check_settlement<1>();
}

TEST_CASE("settlement reference: height, settlement, stress and residual by hand, 2D",
          "[reference][unit]") {
  check_settlement<2>();
}

TEST_CASE("settlement reference: without expected or paper values those metrics are absent",
          "[reference][unit]") {
  auto sim = loam_test::make_simulation<1>(scene<1>());
  auto ref = loam_test::make_reference<1>(*sim, "{type: settlement, load: 1.0e4}");
  auto m = ref->metrics(*sim);
  // The default body is the first one (the cap, 0.2 m), untouched: no settlement; single phase:
  // no pore pressure.
  CHECK(m["final_height"] == Approx(0.2).epsilon(1e-12));
  CHECK(std::fabs(m["final_settlement"]) <= 1e-12);
  CHECK(m.count("settlement_error") == 0);
  CHECK(m.count("settlement_vs_paper") == 0);
  CHECK(m.count("residual_pore_pressure") == 0);
}
