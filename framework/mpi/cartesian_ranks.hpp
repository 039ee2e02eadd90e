#pragma once
// The ranks of a communicator as a non-periodic Cartesian array in D dimensions (docs/parallel.md
// "Decomposition"): MPI_Dims_create picks the shape (an axis may be kept whole: keep_whole),
// MPI_Cart_create keeps the ranks' order (reorder off, so rank r is the same process in both
// communicators), and each rank gets its coordinates: what framework/decomposition.hpp is built
// for.
#include <mpi.h>

#include <array>

#include "mpi_error.hpp"

namespace loam {

template <int D>
class CartesianRanks {
 public:
  explicit CartesianRanks(MPI_Comm world) : world_(world) {
    mpi_check(MPI_Comm_size(world, &size_), "MPI_Comm_size");
    create(std::array<int, D>{});
  }
  /// Re-shape the array so that no block boundary cuts the axes with whole[d] (a periodic axis:
  /// both its faces stay on every rank). Collective. False when every axis is whole and there
  /// is more than one rank: nothing is left to cut.
  bool keep_whole(const std::array<bool, D>& whole) {
    std::array<int, D> dims{};
    bool cut_left = false, reshape = false;
    for (int d = 0; d < D; ++d) {
      dims[d] = whole[d] ? 1 : 0;
      cut_left = cut_left || !whole[d];
      reshape = reshape || (whole[d] && dims_[d] != 1);
    }
    if (!cut_left) return size_ == 1;
    if (reshape) {
      mpi_check(MPI_Comm_free(&comm_), "MPI_Comm_free");
      create(dims);
    }
    return true;
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
  /// MPI_Dims_create fills the zero entries of `dims` (a one keeps an axis whole).
  void create(std::array<int, D> dims) {
    dims_ = dims;
    mpi_check(MPI_Dims_create(size_, D, dims_.data()), "MPI_Dims_create");
    std::array<int, D> periods{};
    mpi_check(MPI_Cart_create(world_, D, dims_.data(), periods.data(), 0, &comm_),
              "MPI_Cart_create");
    mpi_check(MPI_Comm_rank(comm_, &rank_), "MPI_Comm_rank");
    mpi_check(MPI_Cart_coords(comm_, rank_, D, coords_.data()), "MPI_Cart_coords");
  }

  MPI_Comm world_;
  MPI_Comm comm_ = MPI_COMM_NULL;
  std::array<int, D> dims_{}, coords_{};
  int rank_ = 0, size_ = 1;
};

}  // namespace loam
