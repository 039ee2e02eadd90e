// Pressure on a cavity (docs/verification.md N; plugins/loads/cavity_pressure.cpp, the
// `cylinder` and `difference` generators): the loaded wall carries the cavity's area and the
// right resultant, and a pressurised hole in an elastic body gives Lamé's stresses
// (docs/verification.md N).
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>

#include <filesystem>

#include "cli.hpp"
#include "sim_helpers.hpp"

namespace {

/// Sum over the body's particles of the external force the loads put on them now, and the count
/// of loaded particles.
template <int D>
std::pair<std::array<double, D>, size_t> load_resultant(loam::Simulation<D>& sim) {
  sim.prepare_particle_loads();
  const auto& P = sim.sets[0].particles;
  std::array<double, D> f{};
  size_t loaded = 0;
  for (size_t i = 0; i < P.size(); ++i) {
    double m = 0;
    for (int d = 0; d < D; ++d) {
      f[size_t(d)] += P.col(sim.external_force, d)[i];
      m += std::fabs(P.col(sim.external_force, d)[i]);
    }
    loaded += m > 0;
  }
  return {f, loaded};
}

/// A quarter annulus a = 1 m, b = 6 m about the origin (plane strain), slip on the symmetry
/// faces x- and y-, elastic, its hole pressurised with p.
std::string quarter_annulus(const std::string& shape, double cell, double p) {
  return "grid: {extent: [6.5, 6.5], cell_size: " + std::to_string(cell) +
         "}\n"
         "gravity: [0, 0]\n"
         "shape_function: " +
         shape +
         "\n"
         "bodies:\n"
         "  - name: plate\n"
         "    particles_per_cell: 2\n"
         "    generator:\n"
         "      type: difference\n"
         "      of: {type: intersection, of: [{type: sphere, center: [0, 0], radius: 6}, {type: "
         "box, min: [0, 0], max: [6, 6]}]}\n"
         "      minus: [{type: cylinder, center: [0, 0], radius: 1}]\n"
         "    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}\n"
         "boundaries:\n"
         "  - {type: slip, face: x-}\n"
         "  - {type: slip, face: y-}\n"
         "loads:\n"
         "  - type: cavity_pressure\n"
         "    body: plate\n"
         "    cavity: {type: cylinder, center: [0, 0], radius: 1}\n"
         "    pressure: " +
         std::to_string(p) +
         "\n"
         "    time_function: {type: linear_ramp, duration: 0.5}\n"
         "damping: {type: local, alpha: 0.7}\n"
         "time: {end: 3}\n";
}

}  // namespace

TEST_CASE("cavity_pressure: the wall particles carry the hole's area and the pressure's resultant",
          "[cavity][load]") {
  // A quarter hole of radius a: the loaded area sum A_p approximates its arc pi a / 2 (2D, per
  // unit thickness), and the resultant is p a along x and along y (the projections of the
  // quarter arc). The wall's samples (a midpoint rule about s/4 apart, every sample's area to
  // its nearest particle) make both exact up to the midpoint rule's error in the projection,
  // O((s/4a)^2) ~ 1e-4 here: tolerance 1e-3.
  const double p = 1.0e4;
  for (double cell : {0.25, 0.125}) {
    auto sim = loam_test::make_simulation<2>(quarter_annulus("gimp", cell, p));
    // Full load (past the ramp): the time function is of the load's time.
    sim->time = 1.0;
    const auto [f, loaded] = load_resultant(*sim);
    const double fx = f[0] / p, fy = f[1] / p;
    std::printf(
        "cavity_pressure 2D quarter hole a = 1 m, cell %.3f m: %zu wall particles, "
        "resultant/p = (%.5f, %.5f) m against (1, 1): errors %+.2e, %+.2e\n",
        cell, loaded, fx, fy, fx - 1, fy - 1);
    CHECK(std::fabs(fx - 1) < 1e-3);
    CHECK(std::fabs(fy - 1) < 1e-3);
    CHECK(loaded > size_t(0.8 * M_PI / 2 / (cell / 2)));  // about one per spacing of arc
  }
  // 3D: a quarter borehole along z, radius 1 m, 2 m long, in a block: resultant p a L per axis,
  // nothing along the axis (the ends are not loaded).
  const std::string cfg3 =
      "grid: {extent: [3, 3, 4], cell_size: 0.25}\n"
      "gravity: [0, 0, 0]\n"
      "shape_function: gimp\n"
      "bodies:\n"
      "  - name: rock\n"
      "    particles_per_cell: 2\n"
      "    generator:\n"
      "      type: difference\n"
      "      of: {type: box, min: [0, 0, 0], max: [3, 3, 4]}\n"
      "      minus: [{type: cylinder, axis: z, center: [0, 0, 0], radius: 1, from: 1, to: 3}]\n"
      "    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}\n"
      "loads:\n"
      "  - type: cavity_pressure\n"
      "    body: rock\n"
      "    cavity: {type: cylinder, axis: z, center: [0, 0, 0], radius: 1, from: 1, to: 3}\n"
      "    pressure: 1.0e4\n"
      "time: {end: 1}\n";
  auto sim = loam_test::make_simulation<3>(cfg3);
  const auto [f, loaded] = load_resultant(*sim);
  const double fx = f[0] / (p * 2), fy = f[1] / (p * 2);
  std::printf(
      "cavity_pressure 3D quarter borehole a = 1 m, L = 2 m, cell 0.25 m: %zu wall "
      "particles, resultant/(p L) = (%.5f, %.5f, %.2e) m against (1, 1, 0)\n",
      loaded, fx, fy, f[2] / (p * 2));
  CHECK(std::fabs(fx - 1) < 1e-3);
  CHECK(std::fabs(fy - 1) < 1e-3);
  CHECK(f[2] == 0.0);
}

TEST_CASE("cavity_pressure: a pond against a block gives the hydrostatic force and its moment",
          "[cavity][load]") {
  // A block x in [2, 6], y in [0, 4] m; a pond (polygon x in [0, 2], y in [0, 5], vertices in
  // either order) holds a fluid of unit weight gamma to level h = 3 m against its x- face, so
  // p(y) = gamma (h - y) for y < h. Exact: horizontal resultant gamma h^2 / 2 on the block (+x),
  // its moment about the base gamma h^3 / 6 (resultant at h/3), nothing vertical (the pond's
  // floor and free surface have no block beside them; the samples above the level carry zero).
  // The midpoint rule integrates the linear p exactly on each piece; the resultant's only error
  // is the piece straddling y = h, and the moment's the particles' heights (forces act at the
  // particle centres, up to s/2 from the wall samples): tolerances 1e-3 and 2 %.
  const double gamma = 1.6e4, h = 3.0;
  for (const char* vertices :
       {"[[0, 0], [2, 0], [2, 5], [0, 5]]", "[[0, 5], [2, 5], [2, 0], [0, 0]]"}) {
    const std::string cfg =
        "grid: {extent: [6, 6], cell_size: 0.25}\n"
        "gravity: [0, 0]\n"
        "shape_function: gimp\n"
        "bodies:\n"
        "  - name: block\n"
        "    particles_per_cell: 2\n"
        "    generator: {type: box, min: [2, 0], max: [6, 4]}\n"
        "    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}\n"
        "loads:\n"
        "  - {type: cavity_pressure, body: block, cavity: {type: polygon, vertices: " +
        std::string(vertices) +
        "}, unit_weight: 1.6e4, level: 3}\n"
        "time: {end: 1}\n";
    auto sim = loam_test::make_simulation<2>(cfg);
    const auto [f, loaded] = load_resultant(*sim);
    const auto& P = sim->sets[0].particles;
    double moment = 0;  // about the base y = 0
    for (size_t i = 0; i < P.size(); ++i)
      moment += P.col(sim->external_force, 0)[i] * P.col(P.position, 1)[i];
    const double fx = gamma * h * h / 2, mx = gamma * h * h * h / 6;
    std::printf(
        "cavity_pressure pond (vertices %s): %zu loaded particles, resultant (%.1f, %.2e) N/m "
        "against (%.1f, 0): error %+.2e; moment %.1f N m/m against %.1f: error %+.2e\n",
        vertices, loaded, f[0], f[1], fx, f[0] / fx - 1, moment, mx, moment / mx - 1);
    CHECK(std::fabs(f[0] / fx - 1) < 1e-3);
    CHECK(std::fabs(f[1]) < 1e-9 * fx);
    CHECK(std::fabs(moment / mx - 1) < 0.02);
    CHECK(loaded == size_t(h / 0.125));  // the column of particles on the face, below the level
  }
}

TEST_CASE("cavity_pressure: a pressurised hole in an elastic plate gives Lame's stresses",
          "[cavity][verification]") {
  // docs/verification.md N. Thick cylinder (Lamé), plane strain, inner radius a, free outer
  // radius b, pressure p in the hole, tension positive:
  //   sigma_r = -p a^2/(b^2 - a^2) (b^2/r^2 - 1),  sigma_theta = p a^2/(b^2 - a^2) (b^2/r^2 + 1)
  // (b -> infinity: Kirsch's -p (a/r)^2 and +p (a/r)^2). Quarter model a = 1 m, b = 6 m, the
  // pressure ramped over 0.5 s and held, local damping to static at 3 s. The mean of each
  // stress over the particles of a ring must be within 5 % of Lamé's mean over the same
  // particles, for rings between 2a and 4a (the target's r >= 2a; beyond 4a the stress is
  // below 6 % of p and the lattice's staircase outer surface weighs in).
  const double p = 1.0e4, a = 1, b = 6;
  for (const char* shape : {"gimp", "bspline2"}) {
    auto sim = loam_test::make_simulation<2>(quarter_annulus(shape, 0.125, p));
    while (sim->time < 3) REQUIRE(sim->advance(sim->stable_dt()));
    const auto& P = sim->sets[0].particles;
    const double edges[] = {2, 2.5, 3, 3.5, 4};
    for (int k = 0; k < 4; ++k) {
      double sr = 0, st = 0, lr = 0, lt = 0;
      int n = 0;
      for (size_t i = 0; i < P.size(); ++i) {
        const double x = P.col(P.position, 0)[i], y = P.col(P.position, 1)[i];
        const double r = std::hypot(x, y);
        if (r < edges[k] || r >= edges[k + 1]) continue;
        const double c = x / r, s = y / r;
        const double sxx = P.col(P.stress, 0)[i], syy = P.col(P.stress, 1)[i],
                     sxy = P.col(P.stress, 3)[i];
        sr += c * c * sxx + s * s * syy + 2 * c * s * sxy;
        st += s * s * sxx + c * c * syy - 2 * c * s * sxy;
        const double k0 = p * a * a / (b * b - a * a);
        lr += -k0 * (b * b / (r * r) - 1);
        lt += k0 * (b * b / (r * r) + 1);
        ++n;
      }
      REQUIRE(n > 0);
      const double er = sr / lr - 1, et = st / lt - 1;
      std::printf(
          "Lame hole (%s, cell 0.125 m): ring %.1f-%.1f m, %4d particles: sigma_r %.1f "
          "Pa (Lame %.1f, %+.2f %%), sigma_theta %.1f Pa (Lame %.1f, %+.2f %%)\n",
          shape, edges[k], edges[k + 1], n, sr / n, lr / n, 100 * er, st / n, lt / n, 100 * et);
      CHECK(std::fabs(er) < 0.05);
      CHECK(std::fabs(et) < 0.05);
    }
  }
}

TEST_CASE("cavity_pressure and the region generators: bad input gives located errors",
          "[cavity][bad_config]") {
  namespace fs = std::filesystem;
  loam_test::TempDir dir("cavity_bad");
  fs::create_directories(dir.path);
  auto plate = [](const std::string& generator, const std::string& load) {
    return "grid: {extent: [4, 4], cell_size: 0.5}\n"
           "gravity: [0, 0]\n"
           "bodies:\n"
           "  - name: plate\n"
           "    generator: " +
           generator +
           "\n"
           "    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}\n"
           "loads:\n"
           "  - " +
           load + "\ntime: {end: 0.1}\n";
  };
  const std::string hole =
      "{type: difference, of: {type: box, min: [0, 0], max: [4, 4]}, minus: [{type: cylinder, "
      "center: [0, 0], radius: 1}]}";
  const std::string load =
      "{type: cavity_pressure, body: plate, cavity: {type: cylinder, center: "
      "[0, 0], radius: 1}, pressure: 1.0e5}";
  struct Case {
    std::string generator, load, message;
  };
  const std::vector<Case> cases = {
      {hole,
       "{type: cavity_pressure, body: plate, cavity: {type: box, min: [0, 0], max: [1, 1]}, "
       "pressure: 1.0e5}",
       "loads.0.cavity: a 'box' region does not describe its surface"},
      {hole,
       "{type: cavity_pressure, body: plate, cavity: {type: cylinder, axis: x, center: [0, 0], "
       "radius: 1}, pressure: 1.0e5}",
       "loads.0.cavity: in 2D a cylinder is a disk in the plane: its axis must be z"},
      {hole,
       "{type: cavity_pressure, body: plate, cavity: {type: sphere, center: [3, 3], radius: "
       "0.4}, pressure: 1.0e5}",
       "loads.0.cavity: the cavity holds 12 particles of body 'plate'"},
      {"{type: box, min: [0, 0], max: [2, 2]}",
       "{type: cavity_pressure, body: plate, cavity: {type: sphere, center: [3.5, 3.5], radius: "
       "0.4}, pressure: 1.0e5}",
       "loads.0.cavity: no particle of body 'plate' lies on the cavity's wall"},
      {hole,
       "{type: cavity_pressure, body: rock, cavity: {type: sphere, center: [0, 0], "
       "radius: 1}, pressure: 1.0e5}",
       "loads.0.body: unknown body 'rock'"},
      {hole,
       "{type: cavity_pressure, body: plate, cavity: {type: cylinder, center: [0, 0], radius: "
       "1}, unit_weight: 1.0e4}",
       "loads.0.unit_weight: a unit_weight needs the `level` of the fluid's surface"},
      {hole,
       "{type: cavity_pressure, body: plate, cavity: {type: cylinder, center: [0, 0], radius: "
       "1}, level: 2}",
       "loads.0.level: a `level` needs a unit_weight > 0"},
      {hole,
       "{type: cavity_pressure, body: plate, cavity: {type: cylinder, center: [0, 0], radius: "
       "1}}",
       "loads.0.pressure: the load is zero"},
      {"{type: difference, of: {type: box, min: [0, 0], max: [4, 4]}, minus: []}", load,
       "bodies.0.generator.minus: give at least one region to subtract"},
      {"{type: intersection, of: [{type: box, min: [0, 0], max: [4, 4]}]}", load,
       "bodies.0.generator.of: an intersection needs at least two regions"},
      {"{type: difference, of: {type: box, min: [0, 0], max: [4, 4]}, minus: [{type: cylinder, "
       "center: [0, 0], radius: -1}]}",
       load, "bodies.0.generator.minus.0.radius"},
      {"{type: difference, of: {type: box, min: [0, 0], max: [4, 4]}, minus: [{type: cylinder, "
       "axis: y, center: [0, 0], radius: 1}]}",
       load, "bodies.0.generator: minus[0]: in 2D a cylinder is a disk"},
  };
  for (const auto& c : cases) {
    fs::remove_all(dir.path / "out");
    const auto r = loam_test::run_yaml(dir.path, plate(c.generator, c.load));
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.find("run.yaml:") != std::string::npos);
    CHECK(r.output.find(c.message) != std::string::npos);
    CHECK(!fs::exists(dir.path / "out"));
  }
}
