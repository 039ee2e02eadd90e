// The mpirun tests (ctest runs them at 1, 2 and 4 ranks with the MPI build; docs/parallel.md):
// MPI_THREAD_FUNNELED, every test on every rank, rank 0 prints the measured numbers; the exit
// code is the number of failed checks.
#include "mpi_check.hpp"

int main(int argc, char** argv) {
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
  if (provided < MPI_THREAD_FUNNELED) {
    if (loam_mpi_test::rank() == 0) std::printf("FAILED: MPI_THREAD_FUNNELED is not provided\n");
    MPI_Abort(MPI_COMM_WORLD, 1);
  }
  loam_mpi_test::halo_exchange_tests();
  loam_mpi_test::particle_migration_tests();
  const int failed = loam_mpi_test::failures();
  if (loam_mpi_test::rank() == 0) std::printf("%d failed checks\n", failed);
  MPI_Finalize();
  return failed;
}
