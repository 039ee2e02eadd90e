#pragma once
// An MPI call's error code as an exception naming the call (loam's MPI parts; docs/parallel.md).
#include <mpi.h>

#include <stdexcept>
#include <string>

namespace loam {

inline void mpi_check(int code, const char* call) {
  if (code != MPI_SUCCESS) throw std::runtime_error(std::string("MPI error in ") + call);
}

}  // namespace loam
