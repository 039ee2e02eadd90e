// Unit tests of the cpdi shape function (CPDI1, Sadeghirad et al. 2011) in 1D, 2D and 3D:
// partition of unity, zero gradient sum and exact reproduction of linear fields for undeformed
// domains and under a large stretch and shear (F written directly), the D-dimensional gradient
// formula against the paper's 2D corner formula and the 1D difference quotient, the stencil reach
// reported for the slab colouring, the stop with a clear message (inverted domain, too stretched,
// corner outside the grid), and the vibrating bar through the CLI.
#include <catch2/catch.hpp>
#include <cmath>
#include <map>
#include <random>
#include <string>

#include "cli.hpp"
#include "sim_helpers.hpp"
#include "stencil_checks.hpp"

using Catch::Matchers::Contains;
using loam_test::advance;
using loam_test::make_simulation;

namespace {

// A unit square/cube (1 m, 10 cells per axis) with a block of particles, 2 per cell: the domain
// half-size r^0 = h/4 = 0.025 m per axis.
template <int D>
std::string cpdi_scene(const std::string& shape = "cpdi") {
  auto vec = [](double v) {
    std::string s = "[";
    for (int d = 0; d < D; ++d) s += (d ? ", " : "") + std::to_string(v);
    return s + "]";
  };
  return "grid: {extent: " + vec(1.0) + ", cell_size: 0.1}\nshape_function: " + shape +
         "\nbodies:\n  - name: block\n    generator: {type: box, min: " + vec(0.2) +
         ", max: " + vec(0.8) +
         "}\n    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}\n"
         "time: {end: 1}\n";
}

/// Write the same F (row-major) into every particle's deformation gradient.
template <int D>
void set_F(loam::Simulation<D>& sim, const std::array<double, D * D>& F) {
  auto& P = sim.sets[0].particles;
  const int h = P.find("deformation_gradient");
  REQUIRE(h >= 0);
  for (int c = 0; c < D * D; ++c) std::fill(P.col(h, c), P.col(h, c) + P.size(), F[size_t(c)]);
}

/// Random positions in [lo, hi]^D for every particle.
template <int D>
void scatter_positions(loam::Simulation<D>& sim, double lo, double hi, unsigned seed) {
  auto& P = sim.sets[0].particles;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(lo, hi);
  for (size_t i = 0; i < P.size(); ++i)
    for (int d = 0; d < D; ++d) P.col(P.position, d)[i] = u(rng);
}

template <int D>
void check_consistency(loam::Simulation<D>& sim, const std::string& label) {
  const auto e = loam_test::stencil_consistency(sim);
  std::printf(
      "cpdi %dD %-22s: max |sum N - 1| %.2e, h max |sum grad N| %.2e, max |sum N x_I - x_p|/h "
      "%.2e, max |sum x_I grad N - I| %.2e (%zu particles)\n",
      D, label.c_str(), e.sum, e.grad, e.repro, e.grad_repro, sim.sets[0].particles.size());
  CHECK(e.sum < 1e-13);
  CHECK(e.grad < 1e-12);
  CHECK(e.repro < 1e-12);
  CHECK(e.grad_repro < 1e-11);
}

using loam_test::node_values;
using loam_test::NodeValues;

/// Tent function of node n at x (independent of the plugin).
template <int D>
double tent(const loam::Grid<D>& g, size_t n, const std::array<double, D>& x) {
  double w = 1;
  for (int d = 0; d < D; ++d)
    w *= std::max(0.0, 1 - std::fabs(x[size_t(d)] - g.node_coord(n, d)) * g.inv_cell[size_t(d)]);
  return w;
}

}  // namespace

TEST_CASE("cpdi: partition of unity, zero gradient sum, linear reproduction, undeformed (1D-3D)",
          "[shape][unit]") {
  {
    auto sim = make_simulation<1>(cpdi_scene<1>());
    scatter_positions(*sim, 0.03, 0.97, 1);  // anywhere with the domain inside the grid
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    CHECK(sim->shape->nodes_per_particle() == 3);  // merged: domains under a cell
    check_consistency(*sim, "undeformed");
  }
  {
    auto sim = make_simulation<2>(cpdi_scene<2>());
    scatter_positions(*sim, 0.03, 0.97, 2);
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    CHECK(sim->shape->nodes_per_particle() == 9);
    check_consistency(*sim, "undeformed");
  }
  {
    auto sim = make_simulation<3>(cpdi_scene<3>());
    scatter_positions(*sim, 0.03, 0.97, 3);
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    CHECK(sim->shape->nodes_per_particle() == 27);
    check_consistency(*sim, "undeformed");
  }
}

TEST_CASE("cpdi under a large stretch and shear: consistency holds exactly (2D, 3D)",
          "[shape][unit]") {
  // F written directly into the deformation gradient; begin_step turns it into domain vectors.
  // Positions in [0.2, 0.8] keep the stretched domains (up to 0.075 m half-size) in the grid.
  {
    auto sim = make_simulation<2>(cpdi_scene<2>());
    scatter_positions(*sim, 0.2, 0.8, 4);
    set_F<2>(*sim, {3, 0, 0, 0.5});
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    check_consistency(*sim, "stretch diag(3, 0.5)");
    set_F<2>(*sim, {1, 1.5, 0, 1});
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    check_consistency(*sim, "shear [[1,1.5],[0,1]]");
    set_F<2>(*sim, {0.8, 1.5, -0.6, 1.2});  // stretch, shear and rotation together
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    check_consistency(*sim, "general F");
  }
  {
    auto sim = make_simulation<3>(cpdi_scene<3>());
    scatter_positions(*sim, 0.2, 0.8, 5);
    set_F<3>(*sim, {3, 0, 0, 0, 0.5, 0, 0, 0, 1});
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    check_consistency(*sim, "stretch diag(3, .5, 1)");
    set_F<3>(*sim, {1, 1.5, 0, 0, 1, 0.5, 0, 0, 1});
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    check_consistency(*sim, "shear xy 1.5, yz 0.5");
  }
}

TEST_CASE("cpdi: weights and gradients match the paper's corner formulas (1D, 2D)",
          "[shape][unit]") {
  // 1D: S_I = (N_I(x - r) + N_I(x + r)) / 2, grad S_I = (N_I(x + r) - N_I(x - r)) / (2r).
  {
    auto sim = make_simulation<1>(cpdi_scene<1>());
    set_F<1>(*sim, {2.6});
    auto& P = sim->sets[0].particles;
    P.col(P.position)[0] = 0.437;
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    REQUIRE(P.col(P.position)[0] == 0.437);
    const double r = 2.6 * 0.025, x = 0.437;
    double worst = 0;
    for (const auto& [node, v] : node_values(*sim, 0)) {
      const double a = tent<1>(sim->grid, size_t(node), {x - r}),
                   b = tent<1>(sim->grid, size_t(node), {x + r});
      worst = std::max({worst, std::fabs(v[0] - 0.5 * (a + b)),
                        sim->grid.cell[0] * std::fabs(v[1] - (b - a) / (2 * r))});
    }
    std::printf("cpdi 1D vs (N(x-r) + N(x+r))/2 and (N(x+r) - N(x-r))/(2r): max error %.2e\n",
                worst);
    CHECK(worst < 1e-14);
  }
  // 2D, Sadeghirad et al. (2011): corners c1 = x - r1 - r2, c2 = x + r1 - r2, c3 = x + r1 + r2,
  // c4 = x - r1 + r2, V = 4 |r1 x r2|, S_I = (N(c1) + N(c2) + N(c3) + N(c4)) / 4,
  // grad S_I = 1/V [(N(c1) - N(c3)) (r1y - r2y, r2x - r1x) + (N(c2) - N(c4)) (r1y + r2y, -r1x -
  // r2x)].
  // The last F keeps the domain under a cell along both axes (spread 2 (|F_x1| + |F_x2|) r0 =
  // 0.075 and 0.055 m < h = 0.1 m): the corners' stencils are then merged into 3x3 nodes.
  for (auto F :
       {std::array<double, 4>{3, 0, 0, 0.5}, std::array<double, 4>{1, 1.5, 0, 1},
        std::array<double, 4>{0.8, 1.5, -0.6, 1.2}, std::array<double, 4>{1.2, 0.3, -0.2, 0.9}}) {
    const bool merged = F[0] == 1.2;
    auto sim = make_simulation<2>(cpdi_scene<2>());
    set_F<2>(*sim, F);
    auto& P = sim->sets[0].particles;
    const double h0 = 0.025;
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.3, 0.7);
    double worst = 0;
    size_t nodes = 0;
    for (int trial = 0; trial < 50; ++trial) {
      const double x = u(rng), y = u(rng);
      size_t i = sim->sets[0].index_of(0);
      P.col(P.position, 0)[i] = x, P.col(P.position, 1)[i] = y;
      sim->shape->begin_step(*sim);  // may re-sort when the reach grows
      REQUIRE(sim->failure.empty());
      REQUIRE(sim->shape->nodes_per_particle() == (merged ? 9 : 16));
      i = sim->sets[0].index_of(0);
      REQUIRE(P.col(P.position, 0)[i] == x);
      const double r1x = F[0] * h0, r1y = F[2] * h0, r2x = F[1] * h0, r2y = F[3] * h0;
      const double V = 4 * (r1x * r2y - r1y * r2x);
      const std::array<double, 2> c1{x - r1x - r2x, y - r1y - r2y},
          c2{x + r1x - r2x, y + r1y - r2y}, c3{x + r1x + r2x, y + r1y + r2y},
          c4{x - r1x + r2x, y - r1y + r2y};
      auto values = node_values(*sim, i);
      nodes = std::max(nodes, values.size());
      for (const auto& [node, v] : values) {
        const size_t n = size_t(node);
        const double N1 = tent<2>(sim->grid, n, c1), N2 = tent<2>(sim->grid, n, c2),
                     N3 = tent<2>(sim->grid, n, c3), N4 = tent<2>(sim->grid, n, c4);
        const double S = 0.25 * (N1 + N2 + N3 + N4);
        const double gx = ((N1 - N3) * (r1y - r2y) + (N2 - N4) * (r1y + r2y)) / V;
        const double gy = ((N1 - N3) * (r2x - r1x) + (N2 - N4) * (-r1x - r2x)) / V;
        worst = std::max(
            {worst, std::fabs(v[0] - S), 0.1 * std::fabs(v[1] - gx), 0.1 * std::fabs(v[2] - gy)});
      }
    }
    std::printf(
        "cpdi 2D F = [[%g, %g], [%g, %g]] vs the paper's corner formulas: max error (weights, "
        "h * gradients) %.2e, up to %zu distinct nodes per particle\n",
        F[0], F[1], F[2], F[3], worst, nodes);
    CHECK(worst < 1e-13);
    if (merged)
      CHECK(nodes <= 9);
    else
      CHECK(nodes > 9);  // the deformed domain reaches beyond the 3x3 nodes of an undeformed one
  }
}

TEST_CASE("cpdi: reported row reach bounds every touched node row", "[shape][unit]") {
  auto sim = make_simulation<2>(cpdi_scene<2>("{type: cpdi, max_stretch: 10}"));
  auto& P = sim->sets[0].particles;
  const auto& g = sim->grid;
  // Undeformed, 2 particles per cell: corners within h/4 of the particle, one row either way.
  CHECK(sim->shape->rows_below() == 1);
  CHECK(sim->shape->rows_above() == 2);
  for (double Fyy : {1.0, 3.0, 6.0, 9.0}) {
    scatter_positions(*sim, 0.3, 0.7, 6);
    set_F<2>(*sim, {1, 0.5, 0, Fyy});
    sim->shape->begin_step(*sim);
    REQUIRE(sim->failure.empty());
    const int below = sim->shape->rows_below(), above = sim->shape->rows_above();
    const double extent = Fyy * 0.025;  // half-extent along y (r1 has no y component)
    CHECK(below == int(std::floor(extent / g.cell[1])) + 1);
    CHECK(above == below + 1);
    loam::StencilBlock<2> st;
    st.allocate(sim->shape->nodes_per_particle());
    int lo = 0, hi = 0;  // touched rows relative to the particle's row, over nonzero entries
    for (size_t b = 0; b < P.size(); b += loam::kBlock) {
      const int count = int(std::min<size_t>(loam::kBlock, P.size() - b));
      sim->shape->evaluate(g, P, b, count, st);
      for (int p = 0; p < count; ++p) {
        const int row = g.cell_of(P.col(P.position, 1)[b + size_t(p)], 1);
        for (int k = 0; k < st.npp; ++k) {
          const size_t kp = size_t(k) * loam::kBlock + size_t(p);
          if (st.w[kp] == 0 && st.grad[(size_t(k) * 2 + 1) * loam::kBlock + size_t(p)] == 0)
            continue;
          const int node_row = g.node_ijk(size_t(st.node[kp]))[1];
          lo = std::min(lo, node_row - row);
          hi = std::max(hi, node_row - row);
        }
      }
    }
    std::printf("cpdi 2D F_yy = %g: rows touched [%d, %+d], reported [-%d, +%d]\n", Fyy, lo, hi,
                below, above);
    CHECK(-lo <= below);
    CHECK(hi <= above);
  }
}

TEST_CASE("cpdi: a grown reach re-sorts the slab colouring when it is no longer race-free",
          "[shape][unit]") {
  // 2 threads, 50 x 50 cells, 80 x 80 particles: the initial colouring keeps same-colour slabs
  // just far enough apart for the undeformed reach (1 below, 2 above). Stretching every domain
  // to 4.5 cells along y (F_yy = 9, half-size 0.045 m) needs 3 rows below and 4 above; begin_step
  // must then re-sort so that the scatter of this very step is race-free.
  const std::string yaml =
      "grid: {extent: [1, 1], cell_size: 0.02}\nshape_function: {type: cpdi, max_stretch: 10}\n"
      "bodies:\n  - name: block\n    generator: {type: box, min: [0.1, 0.1], max: [0.9, 0.9]}\n"
      "    particles_per_cell: 2\n"
      "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}\ntime: {end: 1}\n";
  auto sim = make_simulation<2>(yaml, 2);
  auto& P = sim->sets[0].particles;
  const size_t slabs_before = sim->sets[0].partition.slabs.size();
  REQUIRE(sim->sets[0].partition.verify(P, sim->grid, 1, 2));
  set_F<2>(*sim, {1, 0, 0, 9});
  const bool safe_without_resort = sim->sets[0].partition.verify(P, sim->grid, 3, 4);
  sim->shape->begin_step(*sim);
  REQUIRE(sim->failure.empty());
  CHECK(sim->shape->rows_below() == 3);
  CHECK(sim->shape->rows_above() == 4);
  std::printf(
      "cpdi reach 1+2 -> 3+4 rows: %zu slabs before, colouring safe without re-sort: %s, %zu "
      "slabs after\n",
      slabs_before, safe_without_resort ? "yes" : "no", sim->sets[0].partition.slabs.size());
  CHECK_FALSE(safe_without_resort);  // the test is meaningful
  CHECK(sim->sets[0].partition.verify(P, sim->grid, sim->shape->rows_below(),
                                      sim->shape->rows_above()));
  // And the step itself runs (scatter, gather, F update) with the stretched domains.
  CHECK_NOTHROW(advance(*sim, 2));
}

TEST_CASE("cpdi stops with a clear message: inverted, too stretched, corner outside the grid",
          "[shape][unit]") {
  const uint32_t id = 17;
  SECTION("det F <= 0 (inverted domain)") {
    auto sim = make_simulation<2>(cpdi_scene<2>());
    auto& P = sim->sets[0].particles;
    const int F = P.find("deformation_gradient");
    const size_t i = sim->sets[0].index_of(id);
    P.col(F, 0)[i] = -0.5;  // F = diag(-0.5, 1)
    try {
      advance(*sim, 1);
      FAIL("no failure");
    } catch (const std::runtime_error& e) {
      std::printf("cpdi inverted: %s\n", e.what());
      CHECK_THAT(e.what(), Contains("particle 17 of body 'block'"));
      CHECK_THAT(e.what(), Contains("CPDI domain inverted or degenerate (det F = -0.5"));
      CHECK_THAT(e.what(), Contains("smaller time step"));
      CHECK_THAT(e.what(), Contains("finer grid"));
      CHECK_THAT(e.what(), Contains("shape function without deforming particle domains"));
    }
  }
  SECTION("det F = 0 (degenerate domain)") {
    auto sim = make_simulation<1>(cpdi_scene<1>());
    auto& P = sim->sets[0].particles;
    P.col(P.find("deformation_gradient"))[sim->sets[0].index_of(3)] = 0.0;
    REQUIRE_THROWS_WITH(advance(*sim, 1), Contains("particle 3 of body 'block'") &&
                                              Contains("inverted or degenerate (det F = 0"));
  }
  SECTION("largest principal stretch above max_stretch (2D, 3D)") {
    auto sim = make_simulation<2>(cpdi_scene<2>());
    auto& P = sim->sets[0].particles;
    const int F = P.find("deformation_gradient");
    const size_t i = sim->sets[0].index_of(id);
    P.col(F, 1)[i] = 4.0;  // shear [[1, 4], [0, 1]]: largest stretch 4.236 > 4
    try {
      advance(*sim, 1);
      FAIL("no failure");
    } catch (const std::runtime_error& e) {
      std::printf("cpdi stretched: %s\n", e.what());
      CHECK_THAT(e.what(), Contains("particle 17 of body 'block'"));
      CHECK_THAT(e.what(), Contains("CPDI domain too distorted (largest principal stretch of F "
                                    "4.236"));
      CHECK_THAT(e.what(), Contains("max_stretch = 4"));
    }
    // 3D: |F|_Frobenius above max_stretch but every stretch below it is fine; a rotated
    // stretch of 4.5 is not (the exact largest singular value, not the Frobenius bound).
    auto s3 = make_simulation<3>(cpdi_scene<3>());
    set_F<3>(*s3, {3.5, 0, 0, 0, 3.5, 0, 0, 0, 0.5});
    s3->shape->begin_step(*s3);
    CHECK(s3->failure.empty());
    const double c = std::cos(0.7), s = std::sin(0.7), l = 4.5;
    // F = Q diag(l, 1, 1) with Q a rotation about z by 0.7 rad
    set_F<3>(*s3, {c * l, -s, 0, s * l, c, 0, 0, 0, 1});
    s3->shape->begin_step(*s3);
    std::printf("cpdi 3D stretched: %s\n", s3->failure.c_str());
    CHECK_THAT(s3->failure, Contains("largest principal stretch of F 4.5 > max_stretch = 4"));
  }
  SECTION("a corner leaves the grid") {
    auto sim = make_simulation<2>(cpdi_scene<2>());
    auto& P = sim->sets[0].particles;
    const size_t i = sim->sets[0].index_of(id);
    P.col(P.position, 0)[i] = 0.01;  // domain [-0.015, 0.035]: 0.15 cells outside (> 0.1)
    try {
      advance(*sim, 1);
      FAIL("no failure");
    } catch (const std::runtime_error& e) {
      std::printf("cpdi outside: %s\n", e.what());
      CHECK_THAT(e.what(), Contains("particle 17 of body 'block' at (0.01, "));
      CHECK_THAT(e.what(), Contains("CPDI domain corner leaves the grid along x (domain spans "
                                    "-0.015 to 0.035 m, grid 0 to 1 m, allowed overhang 0.01 m)"));
      CHECK_THAT(e.what(), Contains("extend the grid"));
    }
    // Within the allowed overhang (round-off drift at a grid face) the run goes on.
    auto ok = make_simulation<2>(cpdi_scene<2>());
    ok->sets[0].particles.col(ok->sets[0].particles.position, 0)[ok->sets[0].index_of(id)] = 0.02;
    CHECK_NOTHROW(advance(*ok, 1));
  }
}

TEST_CASE("vibrating bar with cpdi through the CLI: period and energy (docs/verification.md A)",
          "[shape][verification]") {
  // T = 4L/c = 10 s; tolerances as for linear (docs/verification.md A): period error < 1 %, energy
  // drift < 1 %.
  loam_test::TempDir dir("bar_cpdi");
  auto s = loam_test::run_scene("vibrating_bar.yaml", dir.path, "--set shape_function=cpdi");
  auto v = s["verify"];
  const double period_error = v["period_error"], drift = v["energy_drift"],
               amp = v["amplitude_error"];
  std::printf(
      "vibrating bar cpdi: period %.6f s (exact %.6f), error %.3e; energy drift %.3e; tip "
      "amplitude error %.3e; %g periods observed; %.3g M particle-steps/s\n",
      v["period_measured"].get<double>(), v["period_exact"].get<double>(), period_error, drift, amp,
      v["periods_observed"].get<double>(), s["particle_steps_per_second"].get<double>() / 1e6);
  CHECK(s["status"] == "ok");
  CHECK(v["periods_observed"].get<double>() >= 9);
  CHECK(period_error < 0.01);
  CHECK(drift < 0.01);
}

TEST_CASE(
    "cpdi: the stencil switches between 3^D merged and 4^D corner nodes as domains grow "
    "and shrink, mid-run",
    "[shape][unit]") {
  // The scheme allocates for max_nodes_per_particle() and dispatches on nodes_per_particle()
  // every step: the nodal mass of each step must be the particles' mass whichever stencil the
  // step used (partition of unity through the scatter).
  auto sim = make_simulation<2>(cpdi_scene<2>());
  auto& P = sim->sets[0].particles;
  double particle_mass = 0;
  for (size_t i = 0; i < P.size(); ++i) particle_mass += P.col(P.mass)[i];
  auto nodal_mass = [&] {
    for (const auto& f : sim->scheme->grid_fields())
      if (f.name == "mass") {
        double m = 0;
        for (size_t n = 0; n < sim->grid.num_nodes; ++n)
          m += f.base[n * size_t(f.stride) + size_t(f.offset)];
        return m;
      }
    return -1.0;
  };
  // F = I: spread h/2 (merged); F_xx = 2.5: 1.25 h (corners); back to I (merged).
  const std::array<std::array<double, 4>, 3> Fs{{{1, 0, 0, 1}, {2.5, 0, 0, 1}, {1, 0, 0, 1}}};
  const int expect[3] = {9, 16, 9};
  for (int s = 0; s < 3; ++s) {
    set_F<2>(*sim, Fs[size_t(s)]);
    loam_test::advance(*sim, 1);
    const double m = nodal_mass();
    std::printf("cpdi step %d: %d nodes per particle, nodal mass %.15g of %.15g\n", s,
                sim->shape->nodes_per_particle(), m, particle_mass);
    CHECK(sim->shape->nodes_per_particle() == expect[s]);
    CHECK(std::fabs(m - particle_mass) < 1e-12 * particle_mass);
  }
}
