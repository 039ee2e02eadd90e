// The traction load's surface point (plugins/loads/traction.cpp, apply_at: surface) under shear and
// rotation: the load must act at the centre of the particle's loaded face convected with its
// deformation gradient, x_s = x_p + F (s/2) N (docs/verification.md M, Traction surface point; the
// same convection as CPDI's domain corners). The nodal forces are t A N_I(x_s) with the grid's tent
// functions, so their sum is t A (partition of unity) and their centroid sum f_I x_I / sum f_I is
// x_s exactly (the tents reproduce linear fields). Before, x_s = x_p + (s/2) F_nn N along the fixed
// axis: off by s gamma / 2 tangentially under simple shear gamma, and not turning with a rotation.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <vector>

#include "sim_helpers.hpp"

namespace {

/// One 2D particle at (0.45, 0.45) (cell 0.1, one particle per cell: spacing s = 0.1, loaded
/// face area A = V / s = 0.1 m) under a traction (0, -1000) Pa on its y+ face.
std::unique_ptr<loam::Simulation<2>> one_particle(const char* face) {
  return loam_test::make_simulation<2>(
      "grid: {extent: [1.0, 1.0], cell_size: 0.1}\n"
      "shape_function: gimp\n"
      "bodies:\n"
      "  - name: b\n"
      "    generator: {type: box, min: [0.4, 0.4], max: [0.5, 0.5]}\n"
      "    particles_per_cell: 1\n"
      "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}\n"
      "loads:\n"
      "  - {type: traction, body: b, face: " +
      std::string(face) +
      ", traction: [0, -1000], apply_at: surface}\n"
      "time: {end: 1}\n");
}

struct Resultant {
  double fx = 0, fy = 0, cx = 0, cy = 0;  // total force and its point of action
};

Resultant nodal_resultant(loam::Simulation<2>& sim) {
  std::vector<double> f(sim.grid.num_nodes * 2, 0.0);
  sim.loads[0]->apply_to_grid(sim, loam::NodalVector{f.data(), 2, 0}, 0.0);
  Resultant r;
  double mx = 0, my = 0;
  for (size_t n = 0; n < sim.grid.num_nodes; ++n) {
    r.fx += f[2 * n];
    r.fy += f[2 * n + 1];
    mx += f[2 * n + 1] * sim.grid.node_coord(n, 0);  // sum f_y x_I
    my += f[2 * n + 1] * sim.grid.node_coord(n, 1);
  }
  r.cx = mx / r.fy;
  r.cy = my / r.fy;
  return r;
}

void set_F(loam::Simulation<2>& sim, double f00, double f01, double f10, double f11) {
  auto& P = sim.sets[0].particles;
  const int F = P.find("deformation_gradient");
  REQUIRE(F >= 0);
  REQUIRE(P.size() == 1);
  P.col(F, 0)[0] = f00, P.col(F, 1)[0] = f01, P.col(F, 2)[0] = f10, P.col(F, 3)[0] = f11;
}

}  // namespace

TEST_CASE("traction apply_at surface: the load follows the convected face centre",
          "[traction][load]") {
  // Tolerance 1e-12 m: the tents reproduce a linear field to round-off.
  const double s = 0.1, xp = 0.45, yp = 0.45;
  for (const char* face : {"y+", "y-"}) {
    const double sign = face[1] == '+' ? 1.0 : -1.0;  // outward normal N = sign e_y
    auto sim = one_particle(face);
    struct Case {
      const char* name;
      double F[4];
    };
    const double g = 0.4, th = 0.3;  // shear gamma, rotation angle (rad)
    for (const Case& c :
         {Case{"undeformed", {1, 0, 0, 1}}, Case{"simple shear gamma = 0.4", {1, g, 0, 1}},
          Case{"rotation 0.3 rad", {std::cos(th), -std::sin(th), std::sin(th), std::cos(th)}},
          Case{"stretch 0.8 along y", {1, 0, 0, 0.8}}}) {
      set_F(*sim, c.F[0], c.F[1], c.F[2], c.F[3]);
      const Resultant r = nodal_resultant(*sim);
      // x_s = x_p + F (s/2) N: F N = sign * (F_01, F_11), the second column of F.
      const double ex = xp + sign * 0.5 * s * c.F[1], ey = yp + sign * 0.5 * s * c.F[3];
      std::printf(
          "traction on face %s, %s: force (%.6g, %.6g) N, acting at (%.12f, %.12f), expected "
          "(%.12f, %.12f)\n",
          face, c.name, r.fx, r.fy, r.cx, r.cy, ex, ey);
      CHECK(std::fabs(r.fx) <= 1e-12);
      CHECK(r.fy == Approx(-1000 * 0.1).epsilon(1e-12));
      CHECK(std::fabs(r.cx - ex) <= 1e-12);
      CHECK(std::fabs(r.cy - ey) <= 1e-12);
    }
  }
}
