#pragma once
// The mpirun tests' shared checks (tests/mpi/main.cpp runs them): a check fails if it fails on
// any rank, rank 0 prints it; the exit code is the number of failed checks.
#include <mpi.h>

#include <cstdio>
#include <string>

namespace loam_mpi_test {

inline int& failures() {
  static int n = 0;
  return n;
}

inline int rank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

inline int size() {
  int s = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &s);
  return s;
}

/// A check every rank makes; it fails if it fails on any rank (printed by rank 0).
inline void check(bool ok, const std::string& what) {
  int bad = ok ? 0 : 1, any = 0;
  MPI_Allreduce(&bad, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  if (any) {
    ++failures();
    if (rank() == 0) std::printf("FAILED: %s\n", what.c_str());
  }
}

inline double global_max(double x) {
  double m = 0;
  MPI_Allreduce(&x, &m, 1, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  return m;
}

inline long global_sum(long x) {
  long s = 0;
  MPI_Allreduce(&x, &s, 1, MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  return s;
}

inline long global_max(long x) {
  long m = 0;
  MPI_Allreduce(&x, &m, 1, MPI_LONG, MPI_MAX, MPI_COMM_WORLD);
  return m;
}

/// "2x2" for a rank array.
template <size_t D>
std::string dims_name(const std::array<int, D>& dims) {
  std::string s;
  for (size_t d = 0; d < D; ++d) {
    if (d) s += 'x';
    s += std::to_string(dims[d]);
  }
  return s;
}

void halo_exchange_tests();
void particle_migration_tests();

}  // namespace loam_mpi_test
