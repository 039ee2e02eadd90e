// Unit tests of the core plugins through the C++ API.
#include <catch2/catch.hpp>
#include <cmath>
#include <random>

#include "framework/tensor.hpp"
#include "sim_helpers.hpp"
#include "stencil_checks.hpp"

using loam_test::advance;
using loam_test::make_simulation;

namespace {

std::string block_2d(const std::string& shape, const std::string& extra = "") {
  return "grid: {extent: [1, 1], cell_size: 0.1}\nshape_function: " + shape +
         "\nbodies:\n  - name: b\n    generator: {type: box, min: [0.2, 0.2], max: [0.8, 0.8]}\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}\n" +
         extra + "time: {end: 1}\n";
}

}  // namespace

TEST_CASE("linear shape function: partition of unity, zero gradient sum, linear reproduction",
          "[shape][unit]") {
  auto sim = make_simulation<2>(block_2d("linear"));
  auto& P = sim->sets[0].particles;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (size_t i = 0; i < P.size(); ++i)
    for (int d = 0; d < 2; ++d) P.col(P.position, d)[i] = u(rng);  // anywhere in the grid
  const auto e = loam_test::stencil_consistency(*sim);
  std::printf(
      "linear: max |sum N - 1| %.2e, h max |sum dN| %.2e, max |sum N x_I - x|/h %.2e, "
      "max |sum x_I dN - I| %.2e, entries outside the declared rows %g\n",
      e.sum, e.grad, e.repro, e.grad_repro, e.rows);
  CHECK(e.sum < 1e-14);
  CHECK(e.grad < 1e-13);
  CHECK(e.repro < 1e-13);
  CHECK(e.grad_repro < 1e-12);
  CHECK(e.rows == 0);
}

TEST_CASE("deformation gradient, when requested, stays consistent with the volume update",
          "[unit]") {
  // V and F are updated with the same increment (I + L dt): det F = V / V0 to round-off.
  auto sim = make_simulation<2>(block_2d("linear",
                                         "    velocity: {type: sine, amplitude: [0.3, -0.2], "
                                         "wavenumber: [3, 2]}\n"));
  auto& P = sim->sets[0].particles;
  const int F = sim->request_deformation_gradient();
  std::vector<double> v0(P.col(P.volume), P.col(P.volume) + P.size());
  std::vector<uint32_t> id0(P.id.begin(), P.id.end());
  advance(*sim, 50);
  double worst = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    double det = P.col(F, 0)[i] * P.col(F, 3)[i] - P.col(F, 1)[i] * P.col(F, 2)[i];
    double V0 = 0;
    for (size_t k = 0; k < id0.size(); ++k)
      if (id0[k] == P.id[i]) V0 = v0[k];
    worst = std::max(worst, std::fabs(det - P.col(P.volume)[i] / V0));
  }
  std::printf("max |det F - V/V0| after 50 steps: %.2e\n", worst);
  CHECK(worst < 1e-12);
}

TEST_CASE("linear_elastic: uniaxial strain gives M eps, a rigid rotation keeps the invariants",
          "[material][unit]") {
  auto sim = make_simulation<2>(block_2d("linear"));
  auto& P = sim->sets[0].particles;
  auto& mat = *sim->materials[0];
  const double E = 1e6, nu = 0.3, M = E * (1 - nu) / ((1 + nu) * (1 - 2 * nu));
  const double lambda = E * nu / ((1 + nu) * (1 - 2 * nu));
  std::vector<double> L(4 * loam::kBlock, 0.0);
  loam::MaterialBatch<2> batch;
  batch.begin = 0;
  batch.count = 1;
  batch.L = L.data();
  batch.particles = &P;
  batch.dt = 1e-3;
  for (int c = 0; c < 4; ++c) P.col(P.stress, c)[0] = 0;
  L[0] = -1.0;  // L_xx: compression at rate 1 for 1 ms
  mat.update_stress(batch);
  CHECK(P.col(P.stress, 0)[0] == Approx(-M * 1e-3).epsilon(1e-12));
  CHECK(P.col(P.stress, 1)[0] == Approx(-lambda * 1e-3).epsilon(1e-12));
  CHECK(P.col(P.stress, 2)[0] == Approx(-lambda * 1e-3).epsilon(1e-12));
  // Rigid rotation of a stressed point by 90 degrees in 1000 spin steps (Jaumann rate):
  // the principal stresses are kept and swap axes.
  P.col(P.stress, 0)[0] = -100, P.col(P.stress, 1)[0] = -30, P.col(P.stress, 2)[0] = -40,
                  P.col(P.stress, 3)[0] = 0;
  const int steps = 1000;
  const double omega = M_PI / 2;
  batch.dt = 1.0 / steps;
  std::fill(L.begin(), L.end(), 0.0);
  L[size_t(0 * 2 + 1) * loam::kBlock] = -omega;  // L_xy
  L[size_t(1 * 2 + 0) * loam::kBlock] = omega;   // L_yx: spin, no stretching
  for (int i = 0; i < steps; ++i) mat.update_stress(batch);
  const double sxx = P.col(P.stress, 0)[0], syy = P.col(P.stress, 1)[0],
               sxy = P.col(P.stress, 3)[0];
  const double mean = 0.5 * (sxx + syy),
               rad = std::sqrt(0.25 * (sxx - syy) * (sxx - syy) + sxy * sxy);
  std::printf("rotated stress: xx %.4f yy %.4f xy %.4f; principal %.4f %.4f (exact -100, -30)\n",
              sxx, syy, sxy, mean - rad, mean + rad);
  // The mean stress is unchanged; the forward-Euler Jaumann increment scales the deviatoric
  // radius by sqrt(1 + (2 omega dt)^2) per step (the first-order error of the explicit rate).
  const double growth = std::pow(1 + std::pow(2 * omega * batch.dt, 2), steps / 2.0);
  std::printf("mean %.12f (exact -65); radius %.9f, expected 35 x %.9f = %.9f\n", mean, rad, growth,
              35 * growth);
  CHECK(mean == Approx(-65).epsilon(1e-12));
  CHECK(rad == Approx(35 * growth).epsilon(1e-9));
  CHECK(growth - 1 < 0.005);                 // 0.5 % after a quarter turn in 1000 steps
  CHECK(syy == Approx(-100).epsilon(5e-3));  // axes swapped after 90 degrees
  CHECK(P.col(P.stress, 2)[0] == -40);
}
