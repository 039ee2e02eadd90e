#pragma once
// Whether this process was started by a parallel launcher (mpirun; the launcher's environment
// tells: OMPI_COMM_WORLD_SIZE for OpenMPI, PMI_SIZE for MPICH's Hydra), and the commands that
// cannot run as several ranks. `loam run` runs on ranks in the MPI build (docs/parallel.md);
// compare, bench and element-test, and `run` in a build without MPI, would run the whole job
// once per rank into the same output, so they refuse before they write anything.
#include <cstdlib>
#include <string>

namespace loam {

/// The number of ranks the launcher started (0: not started by one), and which variable says so.
inline long mpi_launch_size(std::string* variable = nullptr) {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* v = std::getenv(var)) {
      if (variable) *variable = std::string(var) + "=" + v;
      return std::strtol(v, nullptr, 10);
    }
  return 0;
}

/// The refusal's message when `command` was started as one of several ranks and cannot run so
/// (`why`: what to do instead), else "".
inline std::string refuse_mpi_launch(const std::string& command, const std::string& why) {
  std::string variable;
  const long ranks = mpi_launch_size(&variable);
  if (ranks <= 1) return "";
  return "error: loam " + command + " was started as one of " + std::to_string(ranks) +
         " MPI ranks (" + variable + "), but it runs on one rank only: every rank would do the " +
         "whole job into the same output. " + why + " (docs/parallel.md says what runs in " +
         "parallel).\n";
}

}  // namespace loam
