#pragma once
// Whether this process was started as one of several MPI ranks (mpirun -np N with N > 1; the
// launcher's environment tells: OMPI_COMM_WORLD_SIZE for OpenMPI, PMI_SIZE for MPICH's Hydra).
// The loam binary runs on one rank only (docs/parallel.md): started N times by mpirun, every
// copy would run the whole scene into the same output directory, so the commands that compute
// refuse before they write anything.
#include <cstdlib>
#include <string>

namespace loam {

/// The refusal's message when the process is one of several ranks, else "".
inline std::string refuse_mpi_launch(const std::string& command) {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"}) {
    const char* v = std::getenv(var);
    if (!v) continue;
    const long ranks = std::strtol(v, nullptr, 10);
    if (ranks > 1)
      return "error: loam " + command + " was started as one of " + std::to_string(ranks) +
             " MPI ranks (" + var + "=" + v +
             "), but it runs on one rank only: every rank would run the whole scene into the "
             "same output directory. Run it without mpirun (docs/parallel.md says what runs in "
             "parallel so far).\n";
  }
  return "";
}

}  // namespace loam
