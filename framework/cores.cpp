#include "cores.hpp"

#include <omp.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace loam {

std::optional<int> cpu_quota_cores(long quota_us, long period_us) {
  if (quota_us <= 0 || period_us <= 0) return std::nullopt;
  return int(std::max(1L, (quota_us + period_us - 1) / period_us));
}

std::optional<int> cpu_quota_cores(const std::string& cpu_max) {
  std::istringstream in(cpu_max);
  std::string quota;
  long period = 0;
  if (!(in >> quota >> period) || quota == "max") return std::nullopt;
  try {
    return cpu_quota_cores(std::stol(quota), period);
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

namespace {

/// This process's CPU quota: cgroup v2, else v1 (the paths a container sees as its own).
std::optional<int> container_quota() {
  std::ifstream v2("/sys/fs/cgroup/cpu.max");
  std::string line;
  if (v2 && std::getline(v2, line)) return cpu_quota_cores(line);
  std::ifstream quota("/sys/fs/cgroup/cpu/cpu.cfs_quota_us"),
      period("/sys/fs/cgroup/cpu/cpu.cfs_period_us");
  long q = 0, p = 0;
  if (quota >> q && period >> p) return cpu_quota_cores(q, p);
  return std::nullopt;
}

}  // namespace

int default_threads() {
  const int omp = omp_get_max_threads();
  if (std::getenv("OMP_NUM_THREADS")) return omp;
  const auto quota = container_quota();
  return quota ? std::min(omp, *quota) : omp;
}

}  // namespace loam
