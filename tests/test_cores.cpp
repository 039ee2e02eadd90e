// The default thread count (framework/cores.hpp): a container's CPU quota caps it. Read from
// cgroup v2's cpu.max ("QUOTA PERIOD", or "max" for none) or v1's quota and period (-1: none),
// rounded up to whole CPUs.
#include <catch2/catch.hpp>
#include <cstdlib>

#include "framework/cores.hpp"

TEST_CASE("cores: a CPU quota caps the default thread count, rounded up", "[cores]") {
  using loam::cpu_quota_cores;
  CHECK(cpu_quota_cores("200000 100000\n") == 2);
  CHECK(cpu_quota_cores("150000 100000") == 2);  // 1.5 CPUs: two threads share them
  CHECK(cpu_quota_cores("50000 100000") == 1);
  CHECK(cpu_quota_cores("6400000 100000") == 64);
  CHECK(!cpu_quota_cores("max 100000"));
  CHECK(!cpu_quota_cores(""));
  CHECK(!cpu_quota_cores("garbage"));
  CHECK(cpu_quota_cores(200000L, 100000L) == 2);
  CHECK(!cpu_quota_cores(-1L, 100000L));
  CHECK(!cpu_quota_cores(100000L, 0L));
  // Without OMP_NUM_THREADS: at least one thread, never more than OpenMP's default.
  const int threads = loam::default_threads();
  std::printf("default threads here: %d\n", threads);
  CHECK(threads >= 1);
}
