// Unit tests of the newtonian_fluid material at one material point: the material-point harness
// (material_point.hpp) doing what a scheme does (V *= det(I + L dt), then update_stress with the
// rate L and dt) in 1D, 2D and 3D, the element-test driver (3D paths), and its parameter checks
// through the command line. The material is tension positive; p is compression positive.
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <vector>

#include "cli.hpp"
#include "app/element_test.hpp"
#include "material_point.hpp"
#include "sim_helpers.hpp"

using loam_test::make_simulation;

namespace {

constexpr double kK = 20e6, kMu = 1e-3, kRho0 = 1000;  // water as in seed 003 (K reduced)

std::string fluid(double mu = kMu, const std::string& extra = "") {
  char m[256];
  std::snprintf(m, sizeof m,
                "{type: newtonian_fluid, bulk_modulus: %g, viscosity: %g, density: %g%s}", kK, mu,
                kRho0, extra.c_str());
  return m;
}

/// The first particle of a one-material simulation, stepped as a scheme steps it:
/// V *= det(I + L dt) (or exp(tr(L) dt) with VolumeUpdate::exp), then update_stress.
template <int D>
struct Point : loam_test::MaterialPoint<D> {
  explicit Point(const std::string& material)
      : loam_test::MaterialPoint<D>(material, loam_test::VolumeUpdate::det, "water") {}
};

/// Compress (factor < 1) or stretch the volume of a point by `factor` in n equal steps of
/// isotropic L (uniaxial in 1D) over dt = 1e-3 s; returns the work -int p dV done on it.
template <int D>
double change_volume(Point<D>& pt, double factor, int n) {
  const double dt = 1e-3;
  const double a = (std::pow(factor, 1.0 / (D * n)) - 1) / dt;  // (1 + a dt)^D per step
  std::vector<double> l(size_t(D * D), 0.0);
  for (int i = 0; i < D; ++i) l[size_t(i * D + i)] = a;
  double work = 0;
  for (int i = 0; i < n; ++i) {
    const double p0 = pt.p(), v0 = pt.volume();
    pt.step(l, dt);
    work -= 0.5 * (p0 + pt.p()) * (pt.volume() - v0);  // trapezoid rule
  }
  return work;
}

}  // namespace

TEST_CASE("newtonian_fluid: pressure from a prescribed compression matches K (rho/rho0 - 1)",
          "[material][unit]") {
  // Reference (hand value): V = 0.99 V0, so rho/rho0 = 1/0.99 and
  // p = K (1/0.99 - 1) = 20e6 * 0.01/0.99 = 202020.2020... Pa. Compression in 100 steps of
  // isotropic L (uniaxial in 1D). The viscous stress is deviatoric, so -tr(sigma)/3 = p in
  // every dimension; in 2D/3D the isotropic rate has no deviator and sigma = -p I.
  // Tolerance 1e-10 relative: the volume is a product of 100 rounded factors (~1e-14) and
  // p = K (rho/rho0 - 1) amplifies its relative error by rho0/(rho - rho0) = 99.
  const double hand = kK * (1 / 0.99 - 1);
  double worst = 0;
  auto check = [&](auto& pt, int dim) {
    change_volume(pt, 0.99, 100);
    const double err = std::fabs(pt.p() - hand) / hand;
    worst = std::max(worst, err);
    std::printf(
        "fluid %dD compression to 0.99 V0: p %.9f Pa, hand K(1/0.99 - 1) %.9f Pa, rel err "
        "%.2e; sigma_xx %.9f sigma_zz %.9f Pa\n",
        dim, pt.p(), hand, err, pt.stress(0), pt.stress(2));
    CHECK(err <= 1e-10);
  };
  Point<1> p1(fluid());
  check(p1, 1);
  Point<2> p2(fluid());
  check(p2, 2);
  Point<3> p3(fluid());
  check(p3, 3);
  for (int k = 0; k < 3; ++k) CHECK(std::fabs(p3.stress(k) + hand) <= 1e-10 * hand);
  for (int k = 3; k < 6; ++k) CHECK(p3.stress(k) == 0.0);
  // Plane strain: D = diag(a, a, 0), so sigma_zz = -p - 2 mu (2a/3), sigma_xx = -p + 2 mu a/3.
  const double a2 = (std::pow(0.99, 1.0 / 200) - 1) / 1e-3;
  const double zz = std::fabs(p2.stress(2) - (p2.stress(0) - 2 * kMu * a2));
  std::printf("fluid 2D plane strain: |sigma_zz - (sigma_xx - 2 mu a)| %.2e Pa\n", zz);
  CHECK(zz <= 1e-12 * hand);
  // 1D: sigma_xx = -p + 2 mu (2/3) L_xx, sigma_yy = sigma_zz = -p - 2 mu L_xx / 3.
  const double lxx = (std::pow(0.99, 1.0 / 100) - 1) / 1e-3;
  const double visc = std::fabs(p1.stress(0) - (-hand + 4 * kMu * lxx / 3));
  std::printf("fluid 1D viscous normal stress: |sigma_xx - (-p + 4/3 mu L_xx)| %.2e Pa\n", visc);
  CHECK(visc <= 1e-10 * hand);
}

TEST_CASE("newtonian_fluid: simple shear at a rate gives the shear stress mu gamma_dot",
          "[material][unit]") {
  // Reference: v_x = gamma_dot y, D_xy = gamma_dot / 2, sigma_xy = 2 mu D_xy = mu gamma_dot,
  // no pressure (det(I + L dt) = 1 for simple shear) and no memory: the stress does not grow
  // with the accumulated shear. Tolerance 1e-12 relative at every increment.
  // (1) Element-test driver, simple_shear to gamma = 0.1 in 0.01 s (gamma_dot = 10 /s,
  // dt = duration / increments). Only sigma_xy is checked there: the driver's particle mass is
  // V times 1 kg/m^3 (its placeholder material), not times the tested material's density, so
  // its pressure for a fluid is meaningless until that is fixed. Pressure: harness (2).
  loam::ElementTest t;
  t.path = "simple_shear";
  t.confining = 0;
  t.strain = 0.1;
  t.increments = 100;
  t.duration = 0.01;
  const double gdot = t.strain / t.duration;
  const auto r = loam::run_element_test(fluid(), t);
  REQUIRE(r.failure.empty());
  double worst = 0;
  for (size_t i = 1; i < r.rows.size(); ++i)
    worst = std::max(worst, std::fabs(r.at(long(i), "sig_xy") - kMu * gdot) / (kMu * gdot));
  std::printf(
      "fluid simple shear (element test): sigma_xy %.15g Pa, mu gamma_dot %.15g Pa, max rel "
      "err over %zu increments %.2e\n",
      r.at(-1, "sig_xy"), kMu * gdot, r.rows.size() - 1, worst);
  CHECK(worst <= 1e-12);

  // (2) Harness: 3D (mu = 1e-3 Pa s, gamma_dot = 10 /s) and 2D plane strain (mu = 0.5 Pa s,
  // gamma_dot = 3 /s), 100 steps of dt = 1e-4 s.
  Point<3> p3(fluid());
  Point<2> p2(fluid(0.5));
  double w3 = 0, w2 = 0, normal = 0;
  for (int i = 0; i < 100; ++i) {
    p3.step({0, 10.0, 0, 0, 0, 0, 0, 0, 0}, 1e-4);
    p2.step({0, 3.0, 0, 0}, 1e-4);
    w3 = std::max(w3, std::fabs(p3.stress(3) - kMu * 10) / (kMu * 10));
    w2 = std::max(w2, std::fabs(p2.stress(3) - 0.5 * 3) / 1.5);
    for (int k : {0, 1, 2, 4, 5}) normal = std::max(normal, std::fabs(p3.stress(k)));
    for (int k : {0, 1, 2}) normal = std::max(normal, std::fabs(p2.stress(k)));
  }
  std::printf(
      "fluid simple shear (harness): 3D sigma_xy %.15g Pa (mu gamma_dot 0.01), rel err %.2e; "
      "2D sigma_xy %.15g Pa (1.5), rel err %.2e; max |other components| %.2e Pa\n",
      p3.stress(3), w3, p2.stress(3), w2, normal);
  CHECK(w3 <= 1e-12);
  CHECK(w2 <= 1e-12);
  CHECK(normal == 0.0);
}

TEST_CASE("newtonian_fluid: the cavitation cutoff holds under tension", "[material][unit]") {
  // Stretch to V = 1.01 V0: the equation of state gives p = K (1/1.01 - 1) = -198019.80 Pa.
  // With cavitation_pressure 10 kPa the pressure stops at -10 kPa (sigma = +10 kPa I exactly,
  // isotropic stretch in 3D); with 0 the fluid carries no tension; without it, the EOS value.
  // Recompressing to 0.995 V0 follows the EOS again (no memory of the cavitated state).
  struct Case {
    std::string extra;
    double expect;
  };
  const double eos = kK * (1 / 1.01 - 1);
  for (const Case& c : {Case{", cavitation_pressure: 10e3", -10e3},
                        Case{", cavitation_pressure: 0", 0.0}, Case{"", eos}}) {
    Point<3> pt(fluid(kMu, c.extra));
    double worst = 0;
    const double dt = 1e-3, a = (std::pow(1.01, 1.0 / 300) - 1) / dt;
    for (int i = 0; i < 100; ++i) {
      pt.step({a, 0, 0, 0, a, 0, 0, 0, a}, dt);
      worst = std::min(worst, pt.p() - std::max(c.expect, kK * (pt.rho() / kRho0 - 1)));
    }
    const double p_stretched = pt.p();
    const double err = std::fabs(p_stretched - c.expect) / std::max(1.0, std::fabs(c.expect));
    const double back = 0.995 / (pt.volume() / (pt.mass() / kRho0));
    change_volume(pt, back, 50);
    const double again = kK * (1 / 0.995 - 1);
    const double err_back = std::fabs(pt.p() - again) / again;
    std::printf(
        "fluid stretched to 1.01 V0 (%s): p %.9f Pa, expected %.9f Pa, rel err %.2e, largest "
        "undershoot below max(cutoff, EOS) %.2e Pa; recompressed to 0.995 V0: p %.6f Pa, EOS "
        "%.6f Pa (rel %.2e)\n",
        c.extra.empty() ? "no cutoff" : c.extra.c_str() + 2, p_stretched, c.expect, err, -worst,
        pt.p(), again, err_back);
    CHECK(err <= 1e-9);
    CHECK(worst >= -1e-9);
    CHECK(err_back <= 1e-9);
  }
  Point<3> pt(fluid(kMu, ", cavitation_pressure: 10e3"));
  const double dt = 1e-3, a = (std::pow(1.01, 1.0 / 300) - 1) / dt;
  for (int i = 0; i < 100; ++i) pt.step({a, 0, 0, 0, a, 0, 0, 0, a}, dt);
  std::printf("fluid cavitated stress: %.12g %.12g %.12g Pa\n", pt.stress(0), pt.stress(1),
              pt.stress(2));
  for (int k = 0; k < 3; ++k) CHECK(std::fabs(pt.stress(k) - 10e3) <= 1e-9 * 10e3);
}

TEST_CASE("newtonian_fluid: wave speed sqrt(K/rho0) at any density, viscous limit included",
          "[material][unit]") {
  // c^2 = dp/drho = K/rho0 for p = K (rho/rho0 - 1): sqrt(20e6/1000) = 141.4213562373095 m/s
  // (hand value), the same for a compressed and a stretched particle (tolerance 1e-14).
  // A very viscous fluid: the explicit viscous limit dt <= rho h^2/(2 D mu) enters as the speed
  // 2 D mu/(rho_min h): mu = 1e5 Pa s, h = 0.25 m, D = 2: 1600 m/s at rho0, 1616 m/s at
  // rho0/1.01; the time step then obeys dt <= rho h^2/(2 D mu) = 1.5625e-4 s.
  const double hand = 141.4213562373095;
  Point<2> pt(fluid());
  const double c0 = pt.wave_speed();
  change_volume(pt, 0.99, 10);
  const double c1 = pt.wave_speed();
  change_volume(pt, 1.02, 10);
  const double c2 = pt.wave_speed();
  std::printf(
      "fluid wave speed: %.13f (rho0), %.13f (compressed 1%%), %.13f (stretched 1%%) m/s; hand "
      "%.13f m/s; max rel err %.2e\n",
      c0, c1, c2, hand,
      std::max({std::fabs(c0 - hand), std::fabs(c1 - hand), std::fabs(c2 - hand)}) / hand);
  for (double c : {c0, c1, c2}) CHECK(std::fabs(c - hand) <= 1e-14 * hand);

  Point<2> v(fluid(1e5));
  const double cv0 = v.wave_speed();
  v.volume() *= 1.01;
  const double cv1 = v.wave_speed();
  v.volume() /= 1.01;
  const double dt = v.sim->stable_dt(), limit = kRho0 * 0.25 * 0.25 / (2 * 2 * 1e5);
  std::printf(
      "fluid mu 1e5 Pa s: speed %.9f m/s (hand 1600), stretched 1%% %.9f m/s (hand %.9f); "
      "stable dt %.6e s, viscous limit %.6e s\n",
      cv0, cv1, 1600 * 1.01, dt, limit);
  CHECK(cv0 == Approx(1600).epsilon(1e-14));
  CHECK(cv1 == Approx(1616).epsilon(1e-14));
  CHECK(dt <= limit);
}

TEST_CASE("newtonian_fluid: a rigid rotation produces no stress", "[material][unit]") {
  // Spin L = [[0, -w], [w, 0]] (D = 0) by 90 degrees in 1000 steps. The material adds no
  // viscous stress (exactly zero shear and deviator) and its pressure is a function of the
  // density alone: with a volume update exact for a spin (V *= exp(tr(L) dt), i.e. V kept)
  // the stress is exactly zero. The schemes' V *= det(I + L dt) = 1 + (w dt)^2 instead dilates
  // the particle under spin by (1 + (w dt)^2)^n, and the fluid then sees that density: printed
  // here, checked to be the only stress (p = K (rho/rho0 - 1), deviator zero).
  const int steps = 1000;
  const double dt = 1e-3, w = M_PI / 2 / steps / dt;
  Point<2> exact(fluid(0.5)), scheme(fluid(0.5));
  exact.volume_update = loam_test::VolumeUpdate::exp;
  double worst = 0;
  for (int i = 0; i < steps; ++i) {
    exact.step({0, -w, w, 0}, dt);
    scheme.step({0, -w, w, 0}, dt);
    for (int k = 0; k < 4; ++k) worst = std::max(worst, std::fabs(exact.stress(k)));
  }
  const double p_expected = kK * (scheme.rho() / kRho0 - 1);
  const double dev =
      std::max({std::fabs(scheme.stress(0) - scheme.stress(1)),
                std::fabs(scheme.stress(1) - scheme.stress(2)), std::fabs(scheme.stress(3))});
  std::printf(
      "fluid rigid rotation 90 deg in %d steps (w dt %.3e): max |stress| %.2e Pa with the "
      "exact volume update; with det(I + L dt): V/V0 - 1 = %.3e, p %.3f Pa (= K(rho/rho0 - 1) "
      "%.3f Pa), deviator %.2e Pa\n",
      steps, w * dt, worst, scheme.volume() / (scheme.mass() / kRho0) - 1, scheme.p(), p_expected,
      dev);
  CHECK(worst == 0.0);
  CHECK(std::fabs(scheme.p() - p_expected) <= 1e-9 * std::fabs(p_expected));
  CHECK(dev == 0.0);
}

TEST_CASE("newtonian_fluid: stored energy equals the work of the pressure", "[material][unit]") {
  // strain_energy = m int_{rho0}^{rho} p/r^2 dr must equal the work -int p dV done along the
  // path (trapezoid rule over 2000 steps: tolerance 1e-5 relative), with and without the
  // cavitation cutoff (stretch to 1.005 V0 passes the cutoff at 10 kPa).
  for (const std::string extra : {"", ", cavitation_pressure: 10e3"}) {
    Point<3> pt(fluid(0, extra));
    const double w1 = change_volume(pt, 0.99, 2000);
    const double e1 = pt.strain_energy();
    Point<3> q(fluid(0, extra));
    const double w2 = change_volume(q, 1.005, 2000);
    const double e2 = q.strain_energy();
    std::printf(
        "fluid energy (%s): compressed 1%%: energy %.9e J, work %.9e J (rel %.2e); stretched "
        "0.5%%: energy %.9e J, work %.9e J (rel %.2e)\n",
        extra.empty() ? "no cutoff" : extra.c_str() + 2, e1, w1, std::fabs(e1 - w1) / w1, e2, w2,
        std::fabs(e2 - w2) / w2);
    CHECK(std::fabs(e1 - w1) <= 1e-5 * w1);
    CHECK(std::fabs(e2 - w2) <= 1e-5 * w2);
  }
}

TEST_CASE("newtonian_fluid: a water column under gravity settles to hydrostatic pressure",
          "[material][unit]") {
  // A 2D column, 0.5 m wide and H = 1 m high, on a fixed base between slip walls, K = 2 MPa
  // (c = 44.7 m/s), mu = 1e-3 Pa s, gravity at t = 0 and local damping, run for 1 s (11 wave
  // periods 4H/c). Linear shape functions give one volumetric strain per cell, so the pressure
  // is compared cell row by cell row: the mean over a row's particles against
  // rho0 g (H - y_c), y_c the row's initial centre height (mass above it). Tolerance 1% of the
  // base pressure rho0 g H (measured about 0.5%, largest in the bottom row).
  const std::string cfg =
      "grid: {origin: [0, 0], extent: [0.5, 1.25], cell_size: 0.05}\n"
      "gravity: [0, -9.81]\n"
      "bodies:\n"
      "  - name: water\n"
      "    generator: {type: box, min: [0, 0], max: [0.5, 1.0]}\n"
      "    particles_per_cell: 2\n"
      "    material: {type: newtonian_fluid, bulk_modulus: 2.0e6, viscosity: 1.0e-3, "
      "density: 1000}\n"
      "boundaries:\n"
      "  - {type: fixed, face: y-}\n"
      "  - {type: slip, face: x-}\n"
      "  - {type: slip, face: x+}\n"
      "damping: {type: local, alpha: 0.3}\n"
      "time: {end: 1.0, cfl: 0.5}\n";
  auto sim = make_simulation<2>(cfg);
  auto& P = sim->sets[0].particles;
  std::vector<int> row(P.size());
  for (size_t i = 0; i < P.size(); ++i) row[i] = int(P.col(P.position, 1)[i] / 0.05);
  while (sim->time < 1.0) loam_test::advance(*sim, 1);
  std::vector<double> sum(20, 0.0);
  std::vector<int> count(20, 0);
  for (size_t i = 0; i < P.size(); ++i) {
    double p = 0;
    for (int k = 0; k < 3; ++k) p -= P.col(P.stress, k)[i] / 3;
    sum[size_t(row[i])] += p;
    ++count[size_t(row[i])];
  }
  const double base = 1000 * 9.81 * 1.0;
  double worst = 0;
  int worst_row = -1;
  for (int j = 0; j < 20; ++j) {
    const double exact = 1000 * 9.81 * (1.0 - (j + 0.5) * 0.05);
    const double err = std::fabs(sum[size_t(j)] / count[size_t(j)] - exact) / base;
    if (err > worst) worst = err, worst_row = j;
  }
  std::printf(
      "fluid column (t = %.3f s, %ld steps): bottom row p %.3f Pa (exact %.3f), max |row p - "
      "rho0 g (H - y_c)| / (rho0 g H) %.2e (row %d)\n",
      sim->time, long(sim->step), sum[0] / count[0], 1000 * 9.81 * 0.975, worst, worst_row);
  CHECK(worst <= 0.01);
}

TEST_CASE("newtonian_fluid: bad parameters give the located error", "[material][unit]") {
  const std::vector<loam_test::BadMaterial> cases = {
      {"bulk_modulus: 2.0e9, viscosity: -1.0e-3",
       ":7:86: error: bodies.0.material.viscosity: -0.001 is out of range [0, inf) Pa s"},
      {"bulk_modulus: 0, viscosity: 1.0e-3",
       ":7:68: error: bodies.0.material.bulk_modulus: 0 is out of range (0, inf) Pa"},
      {"bulk_modulus: 2.0e9, viscosity: 1.0e-3, cavitation_pressure: -1",
       ":7:115: error: bodies.0.material.cavitation_pressure: -1 is out of range [0, inf) Pa"},
  };
  loam_test::check_bad_material("type: newtonian_fluid, density: 1000, ", cases, "water");
}

TEST_CASE(
    "newtonian_fluid: suspension viscosity mu (1 + 2.5 c + 5.2 c^2) where grains share "
    "the water's place",
    "[material][unit]") {
  // Reference: materials/newtonian_fluid.cpp (docs/verification.md F). Simple shear at
  // gamma_dot = 10 /s in 2D plane strain (harness): sigma_xy = mu_eff gamma_dot. A particle whose
  // porosity field is 0.6 (solid concentration c = 0.4) with suspension_viscosity: true has
  // mu_eff = mu (1 + 1.0 + 0.832) = 2.832 mu; without the field (a single-phase run) and with the
  // option off, mu. Tolerance 1e-12 relative.
  auto shear = [](const std::string& extra, bool porosity_field) {
    Point<2> p(fluid(0.5, extra));
    if (porosity_field) {
      const int h = p.sim->request_field({"porosity", 1, "-", "test", {}});
      p.field(h) = 0.6;
    }
    p.step({0, 10.0, 0, 0}, 1e-4);
    return p.stress(3) / (0.5 * 10.0);
  };
  const double with = shear(", suspension_viscosity: true", true);
  const double none = shear(", suspension_viscosity: true", false);
  const double off = shear("", true);
  std::printf(
      "suspension viscosity: mu_eff / mu = %.15g (c = 0.4, exact 2.832), %.15g without a "
      "porosity field, %.15g with the option off\n",
      with, none, off);
  CHECK(with == Approx(2.832).epsilon(1e-12));
  CHECK(none == Approx(1.0).epsilon(1e-12));
  CHECK(off == Approx(1.0).epsilon(1e-12));
}
