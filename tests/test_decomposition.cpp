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
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <tuple>

#include "decomposition_scene.hpp"
#include "framework/body_lattice.hpp"
#include "framework/config.hpp"
#include "framework/registry.hpp"

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
            if (whole.has_affine)
              same = same && box.has_affine && whole.offset(k, j, p) == box.offset(k, j, p);
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

namespace {

/// A generator that records every point it is asked about, around a registered one.
template <int D>
struct Recording : loam::Generator<D> {
  std::unique_ptr<loam::Generator<D>> region;
  mutable std::vector<std::array<double, D>> asked;
  bool contains(const std::array<double, D>& x) const override {
    asked.push_back(x);
    return region->contains(x);
  }
  std::array<double, D> lower() const override { return region->lower(); }
  std::array<double, D> upper() const override { return region->upper(); }
};

/// [v_0, ..., v_D-1] as YAML.
template <int D>
std::string yaml_point(const std::array<double, D>& v) {
  std::string t = "[";
  for (size_t d = 0; d < size_t(D); ++d) t += (d ? ", " : "") + std::to_string(v[d]);
  return t + "]";
}

/// One block of a rank array, with the sum over the ranks played by `sum_over_ranks`.
template <int D>
struct OneBlockRanks : loam::Ranks<D> {
  typename loam::Ranks<D>::CellBlock block;
  std::function<void(double*, int)> sum_over_ranks;
  typename loam::Ranks<D>::CellBlock cell_block(const loam::Grid<D>&) const override {
    return block;
  }
  void sum(double* values, int n) const override { sum_over_ranks(values, n); }
};

template <int D>
void check_body_lattice(const std::array<int, D>& cells, const std::array<int, D>& dims, long ppc) {
  loam::Grid<D> g;
  std::array<double, D> origin{}, extent{}, h{};
  for (int d = 0; d < D; ++d) extent[size_t(d)] = cells[size_t(d)], h[size_t(d)] = 1.0;
  g.init(origin, extent, h);
  // The `sphere` generator: a ball inside the grid (as the build requires of every body),
  // off-centre.
  std::array<double, D> centre{}, upper{};
  for (size_t d = 0; d < size_t(D); ++d)
    centre[d] = 0.45 * double(cells[d]), upper[d] = double(cells[d]);
  const double radius = 0.4 * double(*std::min_element(cells.begin(), cells.end()));
  loam::Diagnostics diag;
  const loam::LoadedConfig cfg = loam::load_config_text(
      "grid: {origin: " + yaml_point<D>(origin) + ", extent: " + yaml_point<D>(upper) +
          ", cell_size: 1}\nbodies:\n  - name: ball\n    generator: {type: sphere, center: " +
          yaml_point<D>(centre) + ", radius: " + std::to_string(radius) +
          "}\n    material: {type: linear_elastic, E: 1, nu: 0, density: 1}\ntime: {end: 1}\n",
      "<test>", {}, diag);
  INFO(diag.format());
  REQUIRE(diag.ok());
  Recording<D> ball;
  ball.region = loam::Registry::instance().create<loam::Generator, D>(
      cfg.params.list("bodies")[0].section("generator"));
  std::array<double, D> s{};
  std::array<long, D> i0{}, i1{};
  for (size_t d = 0; d < size_t(D); ++d) {
    s[d] = 1.0 / double(ppc);
    i0[d] = long(std::ceil((ball.lower()[d]) / s[d] - 0.5 - 1e-9));
    i1[d] = long(std::floor((ball.upper()[d]) / s[d] - 0.5 + 1e-9));
  }
  const loam::Ranks<D> serial_ranks;
  const auto serial = loam::walk_body_lattice<D>(g, serial_ranks, ball, ppc, s, i0, i1);
  REQUIRE(serial.count == serial.x.size());
  for (size_t p = 0; p < serial.x.size(); ++p) REQUIRE(serial.number[p] == p);
  // Pass 1 gathers every block's counts (the sum over the ranks); pass 2 numbers the points.
  const auto blocks = every_block<D>(dims);
  std::vector<double> total;
  std::map<size_t, std::array<double, D>> numbered;
  size_t asked = 0;
  for (int pass = 1; pass <= 2; ++pass)
    for (const auto& c : blocks) {
      OneBlockRanks<D> ranks;
      ranks.block.coord = c;
      ranks.block.dims = dims;
      for (size_t d = 0; d < size_t(D); ++d)
        std::tie(ranks.block.lo[d], ranks.block.hi[d]) = loam::split_range(cells[d], dims[d], c[d]);
      ranks.sum_over_ranks = [&](double* v, int n) {
        if (pass == 1) {
          total.resize(size_t(n), 0.0);
          for (int k = 0; k < n; ++k) total[size_t(k)] += v[k];
        } else {
          std::copy(total.begin(), total.end(), v);
        }
      };
      ball.asked.clear();
      const auto mine = loam::walk_body_lattice<D>(g, ranks, ball, ppc, s, i0, i1);
      // The block tested only points of its own cells, and kept those in the ball.
      for (const auto& x : ball.asked)
        for (size_t d = 0; d < size_t(D); ++d) {
          REQUIRE(int(x[d]) >= ranks.block.lo[d]);
          REQUIRE(int(x[d]) < ranks.block.hi[d]);
        }
      if (pass == 1) asked += ball.asked.size();
      if (pass == 2) {
        CHECK(mine.count == serial.count);
        for (size_t p = 0; p < mine.x.size(); ++p) numbered[mine.number[p]] = mine.x[p];
      }
    }
  // Every lattice point of the body's box was tested once over all blocks, and the blocks'
  // numbers are the serial walk's: each number once, at the same point.
  size_t box_points = 1;
  for (size_t d = 0; d < size_t(D); ++d) box_points *= size_t(i1[d] - i0[d] + 1);
  CHECK(asked == box_points);
  REQUIRE(numbered.size() == serial.x.size());
  for (size_t p = 0; p < serial.x.size(); ++p) CHECK(numbered.at(p) == serial.x[p]);
}

}  // namespace

TEST_CASE(
    "body lattice: a block generates only its own cells' points and numbers them as the serial "
    "walk does",
    "[decomposition][generation]") {
  // framework/body_lattice.hpp: under mpirun no rank walks the whole lattice; the ids still
  // count the body's points in lattice order over the whole grid (the mpirun runs of
  // tests/test_mpi_runs.cpp check the ids of whole runs against the serial run).
  check_body_lattice<1>({23}, {3}, 2);
  check_body_lattice<2>({13, 11}, {3, 2}, 2);
  check_body_lattice<2>({12, 9}, {1, 4}, 3);
  check_body_lattice<3>({9, 8, 7}, {2, 2, 2}, 2);
}
