#pragma once
// How many threads a run uses when --threads is not given (docs/architecture.md, "Threads
// without locks").
#include <optional>
#include <string>

namespace loam {

/// The CPUs a cgroup v2 `cpu.max` line ("QUOTA PERIOD" or "max PERIOD") allows, rounded up;
/// none for "max" or an unreadable line.
std::optional<int> cpu_quota_cores(const std::string& cpu_max);
/// The same from cgroup v1's cpu.cfs_quota_us and cpu.cfs_period_us (quota -1: none).
std::optional<int> cpu_quota_cores(long quota_us, long period_us);

/// OpenMP's default thread count (OMP_NUM_THREADS if set, else the cores this process may run
/// on), capped by the container's CPU quota when OMP_NUM_THREADS is not set: in a container
/// limited to 2 CPUs on a 64-core host, 2 threads rather than 64 time-sliced ones, whose
/// barriers would wait for threads the quota has descheduled.
int default_threads();

}  // namespace loam
