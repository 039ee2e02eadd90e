// The prescribed_velocity condition (plugins/boundaries/prescribed_velocity.cpp): a block whose
// every node is in a prescribed box moves rigidly at v f(t) (particle velocities exact, no
// stress: a rigid translation), a face moves only its own components, and bad input gives
// located errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "cli.hpp"
#include "sim_helpers.hpp"

namespace {

std::string block(const std::string& boundary) {
  return "grid: {extent: [2, 2], cell_size: 0.25}\n"
         "gravity: [0, 0]\n"
         "shape_function: gimp\n"
         "bodies:\n"
         "  - name: block\n"
         "    generator: {type: box, min: [0.5, 0.5], max: [1.5, 1.5]}\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2000}\n"
         "boundaries:\n"
         "  - " +
         boundary + "\ntime: {end: 1}\n";
}

}  // namespace

TEST_CASE("prescribed_velocity: a block held by a moving box translates rigidly at v f(t)",
          "[boundary][prescribed_velocity]") {
  // Every node in the box moves at (0.1, -0.05) f(t), f a ramp over 0.01 s: the particles take
  // the nodes' velocity exactly (sum N = 1) and the velocity gradient is zero (sum grad N = 0),
  // so after 100 steps (fixed dt 1e-4 s) every particle moves at v f(t) to round-off and
  // carries no stress (tolerance 1e-12 m/s, 1e-6 Pa).
  auto sim = loam_test::make_simulation<2>(
      block("{type: prescribed_velocity, min: [0, 0], max: [2, 2], directions: [x, y], "
            "velocity: [0.1, -0.05], time_function: {type: linear_ramp, duration: 0.01}}"));
  for (int k = 0; k < 100; ++k) REQUIRE(sim->advance(1e-4));
  const double f = std::min(1.0, (sim->time - 1e-4) / 0.01);  // the last step's factor
  const auto& P = sim->sets[0].particles;
  double dv = 0, stress = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    dv = std::max(dv, std::fabs(P.col(P.velocity, 0)[i] - 0.1 * f));
    dv = std::max(dv, std::fabs(P.col(P.velocity, 1)[i] + 0.05 * f));
    for (int c = 0; c < 4; ++c) stress = std::max(stress, std::fabs(P.col(P.stress, c)[i]));
  }
  std::printf("prescribed_velocity box: max |v - v f| = %.2e m/s, max |stress| = %.2e Pa\n", dv,
              stress);
  CHECK(dv < 1e-12);
  CHECK(stress < 1e-6);
}

TEST_CASE("prescribed_velocity: bad input gives located errors", "[boundary][bad_config]") {
  namespace fs = std::filesystem;
  loam_test::TempDir dir("prescribed_velocity_bad");
  struct Case {
    std::string boundary, message;
  };
  const std::vector<Case> cases = {
      {"{type: prescribed_velocity, min: [0, 0], max: [2, 2], velocity: [0, 1]}",
       "boundaries.0: a box has no normal: give directions"},
      {"{type: prescribed_velocity, face: y+, velocity: [0, 1], directions: [q]}",
       "boundaries.0.directions: unknown direction 'q'"},
      {"{type: prescribed_velocity, face: y+}", "boundaries.0.velocity"},
      {"{type: prescribed_velocity, face: y+, velocity: [0, 1], time_function: {type: ramp}}",
       "unknown time_function 'ramp'"},
  };
  for (const auto& c : cases) {
    fs::remove_all(dir.path / "out");
    const auto r = loam_test::run_yaml(dir.path, block(c.boundary));
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.find("run.yaml:9:") != std::string::npos);
    CHECK(r.output.find(c.message) != std::string::npos);
    CHECK(!fs::exists(dir.path / "out"));
  }
}
