// `loam bench` smoke test: every fixed scene (single- and two-phase, 2D and 3D, the affine-
// transfer prefixes) builds and runs a few steps. Throughput itself is measured, not tested
// (bench/RESULTS.md); this only catches a scene that no longer starts (e.g. one refused by a new
// set-up check).
#include <catch2/catch.hpp>
#include <cstdio>
#include <string>

#include "cli.hpp"

TEST_CASE("loam bench runs every fixed scene", "[cli][bench]") {
  auto r = loam_test::run_loam(
      "bench --scenes elastic_block_2d two_phase_elastic_block_2d elastic_block_3d "
      "two_phase_elastic_block_3d --threads 1 --steps 2 --repeat 1");
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("error") == std::string::npos);
  for (const char* scene : {"elastic_block_2d ", "two_phase_elastic_block_2d ", "elastic_block_3d ",
                            "two_phase_elastic_block_3d "})
    CHECK(r.output.find(std::string(scene)) != std::string::npos);
  size_t rows = 0;
  for (size_t pos = 0; (pos = r.output.find("M particle-steps/s", pos)) != std::string::npos; ++pos)
    ++rows;
  CHECK(rows == 4);
}

TEST_CASE("loam bench passes --update to the two-phase scenes", "[cli][bench]") {
  // The two-phase scheme has musl and usl: the row must run and say the order it used; usf,
  // which it does not have, is the scheme's located error.
  auto r = loam_test::run_loam(
      "bench --scenes two_phase_elastic_block_2d --threads 1 --steps 2 --repeat 1 --update usl");
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("two_phase_elastic_block_2d 2D linear   usl ") != std::string::npos);
  r = loam_test::run_loam(
      "bench --scenes two_phase_elastic_block_2d --threads 1 --steps 2 --repeat 1 --update usf");
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("error: scheme.update: unknown value 'usf'") != std::string::npos);
}

TEST_CASE("loam bench's apic_ and tpic_ prefixes add the affine transfer", "[cli][bench]") {
  // The prefix must reach the scheme: with bspline2 the affine matrix is D x D more doubles per
  // particle (2D: 88 -> 120 bytes, bench/RESULTS.md), and linear tents under musl are the
  // scheme's located error (they take the affine transfers with usf only).
  for (const char* transfer : {"apic", "tpic"}) {
    const std::string scene = std::string(transfer) + "_elastic_block_2d";
    auto r = loam_test::run_loam("bench --scenes elastic_block_2d " + scene +
                                 " --shape-functions bspline2 --threads 1 --steps 2 --repeat 1");
    std::printf("%s", r.output.c_str());
    CHECK(r.exit_code == 0);
    CHECK(r.output.find("elastic_block_2d   2D bspline2") != std::string::npos);
    CHECK(r.output.find(scene + " 2D bspline2") != std::string::npos);
    CHECK(r.output.find(", 88 B/particle") != std::string::npos);
    CHECK(r.output.find(", 120 B/particle") != std::string::npos);
    r = loam_test::run_loam("bench --scenes " + scene + " --threads 1 --steps 2 --repeat 1");
    CHECK(r.exit_code == 2);
    CHECK(r.output.find("with linear tents needs update: usf") != std::string::npos);
  }
}

TEST_CASE("loam bench's fbar_ prefix adds volumetric: fbar to the single-phase scheme",
          "[cli][bench][locking]") {
  auto r =
      loam_test::run_loam("bench --scenes fbar_elastic_block_2d --threads 1 --steps 2 --repeat 1");
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("fbar_elastic_block_2d 2D linear") != std::string::npos);
  // The two-phase schemes do not offer it: the scheme's located error.
  r = loam_test::run_loam(
      "bench --scenes fbar_two_phase_elastic_block_2d --threads 1 --steps 2 --repeat 1");
  CHECK(r.exit_code == 2);
  CHECK(r.output.find("scheme.volumetric: unknown key") != std::string::npos);
}
