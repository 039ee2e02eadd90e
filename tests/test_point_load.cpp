// The `point` load (plugins/loads/point.cpp): a force at a fixed position, spread to the nodes of
// its cell with linear weights that sum to one. On a free elastic body (no gravity, no
// boundary), the explicit update conserves momentum exactly but for the loads, so the total
// momentum after t must be F t to round-off (Newton's second law for the whole body), wherever
// the point lies inside the body: inside a cell, on a node, on a cell face; in 1D, 2D and 3D.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <string>

#include "sim_helpers.hpp"

namespace {

template <int D>
void check_point_load(const std::string& position, const std::array<double, D>& force) {
  const std::string zero = D == 1 ? "[0]" : D == 2 ? "[0, 0]" : "[0, 0, 0]";
  const std::string one = D == 1 ? "[1]" : D == 2 ? "[1, 1]" : "[1, 1, 1]";
  const std::string lo = D == 1 ? "[0.2]" : D == 2 ? "[0.2, 0.2]" : "[0.2, 0.2, 0.2]";
  const std::string hi = D == 1 ? "[0.6]" : D == 2 ? "[0.6, 0.6]" : "[0.6, 0.6, 0.6]";
  std::string f = "[";
  for (int d = 0; d < D; ++d) f += (d ? ", " : "") + std::to_string(force[size_t(d)]);
  f += "]";
  const double dt = 1e-4;
  const int steps = 200;
  auto sim = loam_test::make_simulation<D>(
      "grid: {origin: " + zero + ", extent: " + one +
      ", cell_size: 0.1}\n"
      "bodies:\n  - name: block\n    generator: {type: box, min: " +
      lo + ", max: " + hi +
      "}\n"
      "    material: {type: linear_elastic, E: 1.0e5, nu: 0.3, density: 1000}\n"
      "loads:\n  - {type: point, position: " +
      position + ", force: " + f +
      "}\n"
      "time: {end: 1, dt: " +
      std::to_string(dt) + "}\n");
  for (int i = 0; i < steps; ++i) REQUIRE(sim->advance(dt));
  const auto momentum = sim->energies().momentum;
  double error = 0, scale = 0;
  for (int d = 0; d < D; ++d) {
    const double expected = force[size_t(d)] * dt * steps;
    error = std::max(error, std::fabs(momentum[size_t(d)] - expected));
    scale = std::max(scale, std::fabs(expected));
  }
  std::printf("point load %dD at %s: momentum after %g s differs from F t by %.2e (relative)\n", D,
              position.c_str(), dt * steps, error / scale);
  CHECK(error <= 1e-10 * scale);
}

}  // namespace

TEST_CASE("point load: a free body's momentum grows as F t, wherever the point lies inside it",
          "[loads][point]") {
  check_point_load<1>("[0.437]", {2.5});
  check_point_load<1>("[0.4]", {-1.0});  // on a node
  check_point_load<2>("[0.413, 0.377]", {3.0, -2.0});
  check_point_load<2>("[0.4, 0.3]", {1.0, 1.0});   // on a node
  check_point_load<2>("[0.45, 0.3]", {0.0, 2.0});  // on a cell face
  check_point_load<3>("[0.413, 0.377, 0.52]", {1.0, -2.0, 0.5});
  check_point_load<3>("[0.3, 0.4, 0.5]", {0.0, 0.0, -1.0});  // on a node
}
