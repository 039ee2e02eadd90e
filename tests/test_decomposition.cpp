// The Cartesian block decomposition (framework/decomposition.hpp; docs/parallel.md), without MPI:
// for every block of several rank arrays in 1D-3D and every shape function of fixed reach, the
// owned nodes of the blocks partition the grid's nodes, every stencil entry of the particles in
// a block's cells lands in its box (owned nodes + ghost layer), and what a block sends to a
// neighbour is, node for node and in order, what the neighbour expects; a block narrower than
// its ghost layer is refused with the reason. The exchange itself runs under mpirun
// (tests/mpi/test_halo_exchange.cpp).
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
