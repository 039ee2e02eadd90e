// `loam bench` smoke test: every fixed scene (single- and two-phase, 2D and 3D) builds and runs
// a few steps. Throughput itself is measured, not tested (bench/RESULTS.md); this only catches a
// scene that no longer starts (e.g. one refused by a new set-up check).
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
