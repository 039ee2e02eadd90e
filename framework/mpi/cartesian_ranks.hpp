#pragma once
// The ranks of a communicator as a non-periodic Cartesian array in D dimensions (docs/parallel.md
// "Decomposition"): MPI_Dims_create picks the shape, MPI_Cart_create keeps the ranks' order
// (reorder off, so rank r is the same process in both communicators), and each rank gets its
// coordinates: what framework/decomposition.hpp is built for.
#include <mpi.h>

#include <array>

#include "mpi_error.hpp"

namespace loam {

template <int D>
class CartesianRanks {
 public:
  explicit CartesianRanks(MPI_Comm world) {
    mpi_check(MPI_Comm_size(world, &size_), "MPI_Comm_size");
    mpi_check(MPI_Dims_create(size_, D, dims_.data()), "MPI_Dims_create");
    std::array<int, D> periods{};
    mpi_check(MPI_Cart_create(world, D, dims_.data(), periods.data(), 0, &comm_),
              "MPI_Cart_create");
    mpi_check(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    mpi_check(MPI_Cart_coords(comm_, rank_, D, coords_.data()), "MPI_Cart_coords");
  }
  ~CartesianRanks() { MPI_Comm_free(&comm_); }
  CartesianRanks(const CartesianRanks&) = delete;
  CartesianRanks& operator=(const CartesianRanks&) = delete;

  MPI_Comm comm() const { return comm_; }
  const std::array<int, D>& dims() const { return dims_; }
  const std::array<int, D>& coords() const { return coords_; }
  int rank() const { return rank_; }
  int size() const { return size_; }

 private:
  MPI_Comm comm_ = MPI_COMM_NULL;
  std::array<int, D> dims_{}, coords_{};
  int rank_ = 0, size_ = 1;
};

}  // namespace loam
