#pragma once
// Particle migration between the blocks of a Cartesian decomposition (docs/parallel.md):
// after the move, every particle whose cell another rank owns goes to that rank with every
// allocated field of the set's registry (the core's and every plugin's: stress, state
// variables, affine moments, ...) and its id, material and body, bit for bit. One packed message
// per neighbour (ExaMPM/Cabana's "one message per neighbour", not CB-Geo's one per particle),
// received from that neighbour by rank and tag (no MPI_ANY_SOURCE), appended in the fixed
// neighbour order, so a run is the same bits at a given rank count. A particle may cross into
// an immediate neighbour only (3^D - 1 around, diagonals included): explicit MPM moves it less
// than a cell per step and a block is at least a ghost layer wide. A particle that jumped
// further stays where it is and is reported (migrate's count, first_stray()): the caller folds
// it into the step's collective stability check, so no rank stops while the others wait.
#include <mpi.h>

#include "framework/decomposition.hpp"
#include "framework/particles.hpp"

namespace loam {

template <int D>
class ParticleMigration {
 public:
  /// `comm`: the Cartesian communicator of `decomposition`; `grid`: the whole grid's geometry.
  /// Both must outlive the migration.
  ParticleMigration(MPI_Comm comm, const Decomposition<D>& decomposition, const Grid<D>& grid);

  /// Send away the particles of P in cells this rank does not own and append those received.
  /// Every rank of `comm` calls it (collective over the neighbours). Returns the particles that
  /// moved beyond the neighbouring blocks (kept, not sent; first_stray() names the first), 0
  /// normally; std::runtime_error if the ranks' particle fields differ.
  long migrate(Particles<D>& P);
  /// The id of the first particle the last migration could not place, or -1.
  long first_stray() const { return first_stray_; }

  /// Over every migration so far: particles and messages this rank sent, and bytes.
  long particles_sent() const { return particles_; }
  long messages_sent() const { return messages_; }
  long bytes_sent() const { return bytes_; }
  /// The immediate neighbours (one message to each per migration).
  int neighbours() const { return int(links_.size()); }

 private:
  MPI_Comm comm_;
  const Decomposition<D>& dec_;
  const Grid<D>& grid_;
  struct Link {
    std::array<int, D> offset;
    int rank, send_tag, recv_tag;
    std::vector<double> send, recv;
  };
  std::vector<Link> links_;
  std::array<int, D> own_lo_{}, own_hi_{};  // this rank's cells [lo, hi) per axis
  std::vector<uint8_t> leaving_;            // per particle: 1 if it is sent away
  long particles_ = 0, messages_ = 0, bytes_ = 0, first_stray_ = -1;

  /// The link to the rank owning cell `cell`, or -1 for this rank; -2 outside the neighbourhood.
  int link_of(const std::array<int, D>& cell) const;
  /// Whether particle i is in a cell of this rank.
  bool in_own_block(const Particles<D>& P, size_t i) const;
};

}  // namespace loam
