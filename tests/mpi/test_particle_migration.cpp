// Particle migration under mpirun (framework/mpi/particle_migration.hpp; docs/parallel.md):
// every rank keeps the particles of its cells of the shared scene, then every particle moves by
// up to two cells in a direction of its own (+-x, +-y, +-z and diagonals, so particles cross
// every face, edge and corner of the blocks), and the ranks migrate. Checked: the particle count
// and the id set are exact (each id on exactly one rank), every particle is on the rank owning
// its cell, every field of every particle (registry fields, id, material, body) is bit for bit
// the serial copy's, a second migration moves nothing, and one message goes to each neighbour.
// 1D, 2D and 3D, with the affine and deformation-gradient fields requested so that plugin fields
// travel too.
#include <cmath>
#include <cstring>
#include <map>

#include "../decomposition_scene.hpp"
#include "framework/mpi/cartesian_ranks.hpp"
#include "framework/mpi/particle_migration.hpp"
#include "mpi_check.hpp"

namespace loam_mpi_test {

namespace {

/// Moves particle i by up to 2 cells in its own direction, staying inside the grid.
template <int D>
void move_particles(loam::Particles<D>& P, const loam::Grid<D>& g) {
  for (size_t i = 0; i < P.size(); ++i)
    for (int d = 0; d < D; ++d) {
      const int dir = int((P.id[i] / (d == 0 ? 1 : d == 1 ? 3 : 9)) % 3) - 1;  // -1, 0, 1
      double& x = P.col(P.position, d)[i];
      const double step =
          dir * (0.5 + 1.5 * std::fabs(std::sin(0.37 * P.id[i] + d))) * g.cell[size_t(d)];
      x = std::fmin(std::fmax(x + step, g.origin[size_t(d)] + 1e-3), g.upper(d) - 1e-3);
    }
}

template <int D>
void migration_case() {
  const int size = loam_mpi_test::size(), me = rank();
  auto sim = loam_test::decomposition_scene<D>("gimp");
  auto& P = sim->sets[0].particles;
  const auto& g = sim->grid;
  // Plugin fields beside the core's: an affine moment (D x D) and a field with an initial value.
  const int extra = P.request({"test_affine_moment", D * D, "m^2/s", "migrated", {}});
  for (size_t i = 0; i < P.size(); ++i)
    for (int c = 0; c < D * D; ++c) P.col(extra, c)[i] = std::cos(double(i) * 0.11 + c);
  for (size_t i = 0; i < P.size(); ++i) {
    P.material[i] = uint16_t(i % 5);
    P.body[i] = uint16_t(i % 3);
  }
  const loam::CartesianRanks<D> ranks(MPI_COMM_WORLD);
  const MPI_Comm cart = ranks.comm();
  const auto& dims = ranks.dims();
  const auto& coords = ranks.coords();
  const loam::Decomposition<D> dec(g, dims, coords, 1, 2);
  // The serial copy, moved the same way: the reference by id.
  loam::Particles<D> serial = P;
  move_particles(serial, g);
  std::map<uint32_t, size_t> by_id;
  for (size_t i = 0; i < serial.size(); ++i) by_id[serial.id[i]] = i;
  // This rank's particles, then the move and the migration.
  auto cell_of = [&](const loam::Particles<D>& Q, size_t i) {
    std::array<int, D> c{};
    for (int d = 0; d < D; ++d) c[size_t(d)] = g.cell_of(Q.col(Q.position, d)[i], d);
    return c;
  };
  std::vector<uint8_t> other(P.size(), 0);
  for (size_t i = 0; i < P.size(); ++i) other[i] = !dec.owns_cell(cell_of(P, i));
  P.erase(other);
  move_particles(P, g);
  long left_before = 0;
  for (size_t i = 0; i < P.size(); ++i) left_before += !dec.owns_cell(cell_of(P, i));
  loam::ParticleMigration<D> migration(cart, dec, g);
  const long strays = migration.migrate(P);
  const long sent_first = migration.particles_sent();
  // Count, ids, ownership, fields.
  const long n = long(serial.size());
  std::vector<long> seen(size_t(n), 0), all(size_t(n), 0);
  long misplaced = 0, differing = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    misplaced += !dec.owns_cell(cell_of(P, i));
    const auto it = by_id.find(P.id[i]);
    if (it == by_id.end()) {
      ++differing;
      continue;
    }
    seen[it->second] += 1;
    const size_t j = it->second;
    bool same = P.material[i] == serial.material[j] && P.body[i] == serial.body[j];
    for (int f = 0; f < P.num_fields(); ++f)
      if (P.has(f))
        for (int c = 0; c < P.info(f).components; ++c)
          same = same && std::memcmp(&P.col(f, c)[i], &serial.col(f, c)[j], 8) == 0;
    differing += !same;
  }
  MPI_Allreduce(seen.data(), all.data(), int(n), MPI_LONG, MPI_SUM, MPI_COMM_WORLD);
  long not_once = 0;
  for (long s : all) not_once += s != 1;
  const long total = global_sum(long(P.size()));
  // A second migration: nothing is misplaced, nothing moves.
  const long strays_second = migration.migrate(P);
  const long sent_second = migration.particles_sent() - sent_first;
  const long messages = migration.messages_sent();
  const long crossed = global_sum(left_before);
  const std::string name =
      std::to_string(D) + "D, " + std::to_string(size) + " ranks (" + dims_name(dims) + ")";
  // Collectives on every rank, printed by rank 0.
  const long misplaced_all = global_sum(misplaced), differing_all = global_sum(differing),
             sent_second_all = global_sum(sent_second), max_messages = global_max(messages) / 2,
             bytes = global_sum(migration.bytes_sent());
  if (me == 0)
    std::printf(
        "migration %-18s %ld particles, %ld crossed a block boundary; after: %ld in total, ids "
        "not on exactly one rank %ld, on a rank not owning their cell %ld, fields differing %ld; "
        "a second migration sent %ld; at most %ld messages per rank per migration, %ld bytes in "
        "all\n",
        name.c_str(), n, crossed, total, not_once, misplaced_all, differing_all, sent_second_all,
        max_messages, bytes);
  check(size == 1 || crossed > 0, name + ": particles crossed block boundaries");
  check(global_sum(strays + strays_second) == 0, name + ": no particle beyond the neighbours");
  check(total == n, name + ": particle count unchanged");
  check(not_once == 0, name + ": every id on exactly one rank");
  check(misplaced_all == 0, name + ": every particle on the rank owning its cell");
  check(differing_all == 0, name + ": every field bit for bit the serial copy's");
  check(sent_second_all == 0, name + ": a second migration moves nothing");
  check(messages == 2L * migration.neighbours(),
        name + ": one message per neighbour and migration");
  // A particle thrown beyond the neighbouring blocks (rank 0's first, to the far end of the
  // grid, with at least 3 blocks along x) stays and is reported; every rank completes.
  if (dims[0] >= 3) {
    long thrown = -1;
    if (coords[0] == 0 && P.size() > 0) {
      thrown = long(P.id[0]);
      P.col(P.position, 0)[0] = g.upper(0) - 1e-3;
    }
    const long stray = migration.migrate(P);
    const bool reported = thrown < 0 ? stray == 0 : stray == 1 && migration.first_stray() == thrown;
    if (me == 0)
      std::printf("migration %-18s a particle thrown across %d blocks: kept and reported: %s\n",
                  name.c_str(), dims[0] - 1, reported ? "yes" : "NO");
    check(reported, name + ": a particle beyond the neighbours is kept and reported");
    check(global_sum(long(P.size())) == n, name + ": and no particle is lost");
  }
}

}  // namespace

void particle_migration_tests() {
  migration_case<1>();
  migration_case<2>();
  migration_case<3>();
}

}  // namespace loam_mpi_test
