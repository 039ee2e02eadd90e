// The Cartesian block decomposition (framework/decomposition.hpp; docs/parallel.md), without MPI:
// for every block of several rank arrays in 1D-3D and every shape function of fixed reach, the
// owned nodes of the blocks partition the grid's nodes, every stencil entry of the particles in
// a block's cells lands in its box (owned nodes + ghost layer), and what a block sends to a
// neighbour is, node for node and in order, what the neighbour expects; a block narrower than
// its ghost layer is refused with the reason; and every shape function evaluated on a grid that
// stores only a block's box of nodes (Grid::store_nodes) gives the whole grid's weights,
// gradients and affine geometry, bit for bit, on the same nodes. The exchange itself runs under
// mpirun (tests/mpi/test_halo_exchange.cpp).
#include <catch2/catch.hpp>
#include <map>

#include "decomposition_scene.hpp"

namespace {

using loam::Decomposition;

template <int D>
std::vector<std::array<int, D>> every_block(const std::array<int, D>& dims) {
  std::vector<std::array<int, D>> blocks;
  loam::NodeBox<D> all;
  all.hi = dims;
  all.for_each([&](const std::array<int, D>& c) { blocks.push_back(c); });
  return blocks;
}

/// Global node index of local index `n` of block c's box.
template <int D>
size_t global_node(const loam::Grid<D>& g, const loam::NodeBox<D>& box, size_t n) {
  size_t global = 0;
  for (int d = 0; d < D; ++d) {
    const size_t width = size_t(box.hi[d] - box.lo[d]);
    global += size_t(box.lo[d] + int(n % width)) * size_t(g.node_stride[size_t(d)]);
    n /= width;
  }
  return global;
}

template <int D>
void check_decompositions(const std::string& shape, const std::vector<std::array<int, D>>& arrays) {
  auto sim = loam_test::decomposition_scene<D>(shape);
  const auto& g = sim->grid;
  const int below = sim->shape->rows_below(), above = sim->shape->rows_above();
  for (const auto& dims : arrays) {
    std::vector<int> owners(g.num_nodes, 0);
    long outside = 0, particles = 0, mismatched = 0, links = 0;
    for (const auto& c : every_block<D>(dims)) {
      const Decomposition<D> dec(g, dims, c, below, above);
      dec.owned().for_each([&](const std::array<int, D>& ijk) {
        size_t n = 0;
        for (int d = 0; d < D; ++d) n += size_t(ijk[d]) * size_t(g.node_stride[size_t(d)]);
        owners[n] += 1;
      });
      const auto arrays_of_block =
          loam_test::scatter_to_box<D>(*sim, dec.box(), [&](const std::array<int, D>& cell) {
            particles += dec.owns_cell(cell);
            return dec.owns_cell(cell);
          });
      outside += arrays_of_block.outside;
      // Every link matches the neighbour's link back, node for node.
      for (const auto& n : dec.neighbours()) {
        ++links;
        const Decomposition<D> other(g, dims, n.coords, below, above);
        const auto* back = static_cast<const typename Decomposition<D>::Neighbour*>(nullptr);
        for (const auto& m : other.neighbours())
          if (m.coords == c) back = &m;
        if (!back || back->shared.size() != n.ghosts.size() ||
            back->ghosts.size() != n.shared.size()) {
          ++mismatched;
          continue;
        }
        for (size_t k = 0; k < n.ghosts.size(); ++k)
          mismatched += global_node(g, dec.box(), n.ghosts[k]) !=
                        global_node(g, other.box(), back->shared[k]);
        for (size_t k = 0; k < n.shared.size(); ++k)
          mismatched += global_node(g, dec.box(), n.shared[k]) !=
                        global_node(g, other.box(), back->ghosts[k]);
      }
    }
    long not_once = 0;
    for (int o : owners) not_once += o != 1;
    std::string name;
    for (int d = 0; d < D; ++d) {
      if (d) name += 'x';
      name += std::to_string(dims[size_t(d)]);
    }
    INFO(D << "D " << shape << ", ranks " << name);
    std::printf(
        "%dD %-8s ranks %-6s: nodes not owned exactly once %ld, stencil entries outside the box "
        "%ld, particles owned %ld of %zu, links %ld, mismatched link nodes %ld\n",
        D, shape.c_str(), name.c_str(), not_once, outside, particles, sim->sets[0].particles.size(),
        links, mismatched);
    CHECK(not_once == 0);
    CHECK(outside == 0);
    CHECK(size_t(particles) == sim->sets[0].particles.size());
    CHECK(mismatched == 0);
  }
}

}  // namespace

TEST_CASE("decomposition: owned nodes partition the grid, boxes hold every stencil, links match",
          "[decomposition][mpi]") {
  for (const std::string shape : {"linear", "gimp", "bspline2"}) {
    check_decompositions<1>(shape, {{1}, {2}, {3}, {4}, {7}});
    check_decompositions<2>(shape, {{1, 1}, {2, 1}, {1, 2}, {2, 2}, {3, 2}, {4, 5}});
    check_decompositions<3>(shape, {{1, 1, 1}, {2, 1, 1}, {2, 2, 1}, {2, 2, 2}, {3, 2, 2}});
  }
}

TEST_CASE("decomposition: a block narrower than the ghost layer is refused with the reason",
          "[decomposition][mpi]") {
  auto sim = loam_test::decomposition_scene<1>("bspline2");  // 23 cells, reach 2
  const auto& g = sim->grid;
  CHECK_NOTHROW(Decomposition<1>(g, {11}, {0}, 1, 2));  // 2 or 3 cells per block
  try {
    Decomposition<1>(g, {12}, {0}, 1, 2);  // 1 or 2 cells per block
    FAIL("no error");
  } catch (const std::invalid_argument& e) {
    std::printf("23 cells over 12 ranks with bspline2: %s\n", e.what());
    CHECK(std::string(e.what()).find("needs at least 2 cells") != std::string::npos);
  }
  // Linear tents reach one row: one cell per block is enough.
  CHECK_NOTHROW(Decomposition<1>(g, {23}, {22}, 0, 1));
}

namespace {

/// Blocks of `dims`: each block's particles evaluated on the whole grid and on a grid storing
/// only the block's box; counts entries that differ (weights, gradients, offsets and D_p^-1 bit
/// for bit; the node by its global indices) and local indices outside the box.
template <int D>
void check_box_evaluation(const std::string& shape, const std::array<int, D>& dims) {
  auto sim = loam_test::decomposition_scene<D>(shape);
  const auto& g = sim->grid;
  const auto& P = sim->sets[0].particles;
  sim->shape->begin_step(*sim);
  long differing = 0, outside = 0, entries = 0, boxes_not_whole = 0;
  for (const auto& c : every_block<D>(dims)) {
    const Decomposition<D> dec(g, dims, c, sim->shape->rows_below(), sim->shape->rows_above());
    loam::Grid<D> local = g;
    local.store_nodes(dec.box().lo, dec.box().hi);
    boxes_not_whole += local.num_nodes < g.num_nodes;
    loam::StencilBlock<D> whole, box;
    whole.allocate(sim->shape->max_nodes_per_particle());
    box.allocate(sim->shape->max_nodes_per_particle());
    for (size_t b = 0; b < P.size(); b += loam::kBlock) {
      const int count = int(std::min<size_t>(loam::kBlock, P.size() - b));
      whole.affine = box.affine = loam::StencilBlock<D>::kInertia;
      sim->shape->evaluate(g, P, b, count, whole);
      sim->shape->evaluate(local, P, b, count, box);
      for (int p = 0; p < count; ++p) {
        std::array<int, D> cell{};
        for (int d = 0; d < D; ++d)
          cell[size_t(d)] = g.cell_of(P.col(P.position, d)[b + size_t(p)], d);
        if (!dec.owns_cell(cell)) continue;
        for (int k = 0; k < sim->shape->nodes_per_particle(); ++k) {  // CPDI: this step's
          const size_t kp = size_t(k) * loam::kBlock + size_t(p);
          ++entries;
          if (box.node[kp] < 0 || size_t(box.node[kp]) >= local.num_nodes) {
            ++outside;
            continue;
          }
          bool same = whole.w[kp] == box.w[kp] &&
                      local.node_ijk(size_t(box.node[kp])) == g.node_ijk(size_t(whole.node[kp]));
          for (int j = 0; j < D; ++j) {
            const size_t kj = (size_t(k) * D + size_t(j)) * loam::kBlock + size_t(p);
            same = same && whole.grad[kj] == box.grad[kj];
            if (whole.has_affine) same = same && box.has_affine && whole.dx[kj] == box.dx[kj];
          }
          if (whole.has_affine)
            for (int j = 0; j < D; ++j)
              same = same && whole.inertia_inv[size_t(j) * loam::kBlock + size_t(p)] ==
                                 box.inertia_inv[size_t(j) * loam::kBlock + size_t(p)];
          differing += !same;
        }
      }
    }
  }
  std::printf(
      "%dD %-8s on block boxes: %ld stencil entries of owned particles, %ld differ from the "
      "whole grid's, %ld outside the box (%ld of the boxes smaller than the grid)\n",
      D, shape.c_str(), entries, differing, outside, boxes_not_whole);
  CHECK(entries > 0);
  CHECK(differing == 0);
  CHECK(outside == 0);
  CHECK(boxes_not_whole > 0);
}

}  // namespace

TEST_CASE("decomposition: shape functions on a block's node box give the whole grid's stencil",
          "[decomposition][mpi][shape]") {
  for (const std::string shape : {"linear", "gimp", "bspline2", "cpdi"}) {
    check_box_evaluation<1>(shape, {3});
    check_box_evaluation<2>(shape, {3, 2});
    check_box_evaluation<3>(shape, {2, 2, 2});
  }
}

namespace {

/// Cell links (Decomposition::cell_links) of every block of a rank array: what a block sends
/// to a neighbour is, cell for cell and in order, what the neighbour expects back, every ghost
/// cell belongs to the neighbour it is sent to, and the ghost cells of a block are exactly the
/// cells within one cell of it outside it, each in one link.
template <int D>
void check_cell_links(const std::vector<std::array<int, D>>& arrays) {
  auto sim = loam_test::decomposition_scene<D>("linear");
  const auto& g = sim->grid;
  for (const auto& dims : arrays) {
    long mismatched = 0, links = 0, ghost_errors = 0;
    for (const auto& c : every_block<D>(dims)) {
      const Decomposition<D> dec(g, dims, c, 0, 1);
      const auto mine = dec.cell_links(g.cell_stride);
      std::map<size_t, int> ghost_count;
      for (const auto& n : mine) {
        ++links;
        const Decomposition<D> other(g, dims, n.coords, 0, 1);
        const auto back_links = other.cell_links(g.cell_stride);
        const typename Decomposition<D>::Neighbour* back = nullptr;
        for (const auto& m : back_links)
          if (m.coords == c) back = &m;
        if (!back || back->shared != n.ghosts || back->ghosts != n.shared) ++mismatched;
        for (size_t cell : n.ghosts) {
          ++ghost_count[cell];
          std::array<int, D> ijk{};
          for (int d = D - 1; d >= 0; --d) {
            ijk[size_t(d)] = int(cell / size_t(g.cell_stride[size_t(d)]));
            cell %= size_t(g.cell_stride[size_t(d)]);
          }
          ghost_errors += !other.owns_cell(ijk);
        }
      }
      // The ring of cells around the block, inside the grid.
      long ring = 0;
      loam::NodeBox<D> all;
      for (int d = 0; d < D; ++d) all.hi[d] = g.cells[d];
      all.for_each([&](const std::array<int, D>& ijk) {
        if (dec.owns_cell(ijk)) return;
        bool near = true;
        for (int d = 0; d < D; ++d) {
          const auto [lo, hi] = dec.cells_of(c, d);
          near = near && ijk[size_t(d)] >= lo - 1 && ijk[size_t(d)] <= hi;
        }
        if (!near) return;
        ++ring;
        size_t i = 0;
        for (int d = 0; d < D; ++d) i += size_t(ijk[size_t(d)]) * size_t(g.cell_stride[size_t(d)]);
        ghost_errors += ghost_count.count(i) == 0 || ghost_count[i] != 1;
      });
      ghost_errors += long(ghost_count.size()) != ring;
    }
    INFO(D << "D, " << links << " cell links");
    std::printf("%dD cell links of %d-block arrays: %ld links, %ld mismatched, %ld ghost errors\n",
                D, int(every_block<D>(dims).size()), links, mismatched, ghost_errors);
    CHECK(mismatched == 0);
    CHECK(ghost_errors == 0);
  }
}

}  // namespace

TEST_CASE("decomposition: cell links cover the ring of cells around each block and match",
          "[decomposition][mpi]") {
  // The per-cell sums of a scheme (pressure smoothing of the two-phase scheme) are completed
  // over these links after the move (docs/parallel.md).
  check_cell_links<1>({{2}, {3}, {7}});
  check_cell_links<2>({{2, 1}, {2, 2}, {3, 2}, {4, 5}});
  check_cell_links<3>({{2, 2, 1}, {2, 2, 2}, {3, 2, 2}});
}
