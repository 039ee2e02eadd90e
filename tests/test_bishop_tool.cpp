// tools/bishop.py, the limit-equilibrium check of the strength reduction
// (docs/strength_reduction.md; Bishop's simplified method over circular slip surfaces), against the
// two textbook solutions it reproduces: an infinite cohesionless slope, F = tan(phi) / tan(beta)
// (shallow circles approach it from above), and Taylor's (1937) stability number for phi = 0 toe
// circles at beta = 60 deg, N_s = c / (F gamma H) = 0.191. Steeper faces are not reproduced yet: at
// 75 and 90 deg the tool's minimum is 3 % and 12 % less critical than Taylor's 0.219 and 0.261
// (docs/verification.md J); they are printed only.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cli.hpp"

namespace {

nlohmann::json bishop(const std::string& args) {
  // The Debian interpreter that tools/setup.sh gives numpy.
  auto r = loam_test::run_command("/usr/bin/python3 " + std::string(LOAM_SOURCE_DIR) +
                                  "/tools/bishop.py --json " + args);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  return nlohmann::json::parse(r.output);
}

}  // namespace

TEST_CASE("bishop tool: an infinite cohesionless slope and Taylor's phi = 0 toe circle",
          "[bishop][tools]") {
  const double inf = std::tan(35 * M_PI / 180) / std::tan(30 * M_PI / 180);
  const double f = bishop("--height 10 --angle 30 --gamma 20000 --c 0 --phi 35")["factor_of_safety"]
                       .get<double>();
  std::printf(
      "c = 0, phi = 35, beta = 30: F = %.5f against tan(phi)/tan(beta) = %.5f (%+.3f %%, "
      "tolerance 1 %%)\n",
      f, inf, 100 * (f / inf - 1));
  CHECK(f == Approx(inf).epsilon(0.01));
  CHECK(f >= inf * (1 - 1e-6));  // circles are never more critical than the infinite slope
  const double n60 =
      bishop("--height 10 --angle 60 --gamma 20000 --c 20000 --phi 0")["taylor_stability_number"]
          .get<double>();
  std::printf("phi = 0, beta = 60: N_s = %.4f against Taylor's 0.191 (%+.2f %%, tolerance 2 %%)\n",
              n60, 100 * (n60 / 0.191 - 1));
  CHECK(n60 == Approx(0.191).epsilon(0.02));
  for (const auto& [beta, taylor] : {std::pair<int, double>{75, 0.219}, {90, 0.261}}) {
    const double n = bishop("--height 10 --angle " + std::to_string(beta) +
                            " --gamma 20000 --c 20000 --phi 0")["taylor_stability_number"]
                         .get<double>();
    std::printf("phi = 0, beta = %d: N_s = %.4f against Taylor's %.3f (%+.1f %%, not asserted)\n",
                beta, n, taylor, 100 * (n / taylor - 1));
  }
  auto bad = loam_test::run_command("/usr/bin/python3 " + std::string(LOAM_SOURCE_DIR) +
                                    "/tools/bishop.py --height 10 --angle 95 --gamma 2e4 --c 1 "
                                    "--phi 0");
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("need height > 0, 0 < angle <= 90") != std::string::npos);
}
