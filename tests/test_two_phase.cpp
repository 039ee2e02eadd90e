// The two_phase_single_point scheme (schemes/two_phase_single_point.cpp) against Terzaghi's
// consolidation (VERIFICATION.md C, seed 001 small strain), through the real CLI, and its
// set-up errors.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include "cli.hpp"

TEST_CASE("two-phase: seed 001 Terzaghi column within 0.02 of the series at T = 0.05 to 1",
          "[verification][two_phase]") {
  // Reference: VERIFICATION.md C, p(z,t)/p0 series with c_v = k M / gamma_w = 1.0194 m^2/s,
  // one-way drainage, H = 1 m. Target (issue 6): max |p/p0 - exact| <= 0.02 at each T, the
  // degree of consolidation within 0.01.
  loam_test::TempDir dir("terzaghi");
  auto s = loam_test::run_scene("seed001_terzaghi.yaml", dir.path,
                                "--threads 1 --set output.every_time=10");
  auto v = s["verify"];
  for (const char* T : {"0.05", "0.1", "0.2", "0.5", "1"}) {
    const double e = v[std::string("max_error_T") + T],
                 u = v[std::string("consolidation_degree_error_T") + T];
    std::printf("Terzaghi T = %-4s: max |p/p0 - exact| = %.4f, |U - U_exact| = %.2e\n", T, e,
                std::fabs(u));
    CHECK(e <= 0.02);
    CHECK(std::fabs(u) <= 0.01);
  }
  std::printf("Terzaghi: %ld steps, %.1f s wall\n", s["steps"].get<long>(),
              s["wall_seconds"].get<double>());
}
