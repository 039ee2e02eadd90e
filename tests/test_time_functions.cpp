// Time functions (docs/verification.md T; plugins/time_functions/): exact values at their
// breakpoints and between them, located errors for bad input (a table whose times do not
// increase, inline or in a file), and the factor reaching the load: a free block's momentum is
// the traction's impulse F sum_k f(t_k) dt, and `ramp_time: T` is bitwise
// `time_function: {type: linear_ramp, duration: T}`.
#include <yaml-cpp/yaml.h>

#include <catch2/catch.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>

#include "cli.hpp"
#include "framework/time_function.hpp"
#include "sim_helpers.hpp"

namespace {

namespace fs = std::filesystem;

/// A time function from its YAML text (validated as a run file's would be; REQUIREs no errors).
std::unique_ptr<loam::TimeFunction<2>> make(const std::string& yaml,
                                            const std::string& file = "tf.yaml") {
  loam::ValidationContext ctx;
  ctx.file = file;
  ctx.dimension = 2;
  loam::Diagnostics diag;
  loam::Params p = loam::validate_plugin(YAML::Load(yaml), "time_function", loam::kDimension,
                                         "time_function", loam::Location{file, 1, 1}, ctx, diag);
  INFO(diag.format());
  REQUIRE(diag.ok());
  return loam::Registry::instance().create<loam::TimeFunction, 2>(p);
}

/// A 0.5 x 0.5 m elastic block in a 1 x 1 m grid without gravity, with `loads`.
std::string block(const std::string& loads) {
  return "grid: {extent: [1.0, 1.0], cell_size: 0.1}\n"
         "gravity: [0, 0]\n"
         "shape_function: gimp\n"
         "bodies:\n"
         "  - name: block\n"
         "    generator: {type: box, min: [0.25, 0.25], max: [0.75, 0.75]}\n"
         "    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2000}\n" +
         loads + "time: {end: 1}\n";
}

}  // namespace

TEST_CASE("time functions: exact values at the breakpoints and between them", "[time_function]") {
  auto c = make("{type: constant, value: 2.5}");
  CHECK(c->value(0) == 2.5);
  CHECK(c->value(7) == 2.5);
  auto r = make("{type: linear_ramp, duration: 3}");
  CHECK(r->value(-1) == 0.0);
  CHECK(r->value(0) == 0.0);
  CHECK(r->value(1.5) == 0.5);
  CHECK(r->value(3) == 1.0);
  CHECK(r->value(5) == 1.0);
  auto r2 = make("{type: linear_ramp, duration: 2, start: 1, from: 4, to: 2}");
  CHECK(r2->value(0.5) == 4.0);
  CHECK(r2->value(2) == 3.0);
  CHECK(r2->value(3) == 2.0);
  // Seed 002's blast: 2.5 GPa at 0.017 s, over at 0.034 s.
  auto b = make("{type: triangular_pulse, peak_time: 0.017, end_time: 0.034, peak: 2.5e9}");
  CHECK(b->value(0) == 0.0);
  CHECK(b->value(0.017) == 2.5e9);
  CHECK(b->value(0.0085) == Approx(1.25e9).epsilon(1e-15));
  CHECK(b->value(0.0255) == Approx(1.25e9).epsilon(1e-14));
  CHECK(b->value(0.034) == 0.0);
  CHECK(b->value(0.05) == 0.0);
  auto t = make("{type: table, times: [0, 1, 3], values: [0, 2, -1]}");
  CHECK(t->value(-1) == 0.0);
  CHECK(t->value(0) == 0.0);
  CHECK(t->value(1) == 2.0);
  CHECK(t->value(2) == 0.5);
  CHECK(t->value(3) == -1.0);
  CHECK(t->value(4) == -1.0);
  auto s = make("{type: sine, amplitude: 2, frequency: 0.5, phase: 90, offset: 1}");
  CHECK(s->value(0) == Approx(3).epsilon(1e-15));
  CHECK(s->value(0.5) == Approx(1).epsilon(1e-15));
  CHECK(s->value(1) == Approx(-1).epsilon(1e-15));
  // A CSV table with a header, relative to the run file's folder.
  loam_test::TempDir d("time_table");
  fs::create_directories(d.path);
  std::ofstream(d.path / "pulse.csv") << "time,factor\n0,0\n1,2\n3,-1\n";
  auto f = make("{type: table, file: pulse.csv}", (d.path / "run.yaml").string());
  for (double x : {-1.0, 0.0, 0.5, 1.0, 2.0, 3.0, 4.0}) CHECK(f->value(x) == t->value(x));
}

TEST_CASE("time functions: bad input gives located errors", "[time_function][bad_config]") {
  loam_test::TempDir d("time_bad");
  fs::create_directories(d.path);
  std::ofstream(d.path / "back.csv") << "0,0\n2,1\n1,3\n";
  struct Case {
    std::string function, message;
  };
  const std::vector<Case> cases = {
      {"{type: table, times: [0, 2, 1], values: [0, 1, 3]}",
       "time_function.times: the times must increase strictly: point 3 (t = 1) is not after "
       "point 2 (t = 2)"},
      {"{type: table, file: back.csv}",
       "time_function.file: the times must increase strictly: point 3 (t = 1)"},
      {"{type: table, times: [0, 1], values: [0]}",
       "time_function.values: give one value per time (2 times, 1 values)"},
      {"{type: table, file: missing.csv}", "time_function.file: cannot read"},
      {"{type: table, times: [0, 1], values: [0, 1], file: back.csv}",
       "time_function: give either `times` and `values` or `file`"},
      {"{type: triangular_pulse, peak_time: 0.02, end_time: 0.01}",
       "time_function.end_time: end_time must be after peak_time"},
      {"{type: linear_ramp, duration: 0}", "time_function.duration"},
      {"{type: ramp, duration: 1}", "unknown time_function 'ramp'"},
  };
  for (const auto& c : cases) {
    const auto r = loam_test::run_yaml(
        d.path, block("loads:\n  - {type: traction, body: block, face: y+, traction: [0, -1000], "
                      "time_function: " +
                      c.function + "}\n"));
    INFO(r.output);
    CHECK(r.exit_code == 2);
    CHECK(r.output.find("run.yaml:9:") != std::string::npos);
    CHECK(r.output.find(c.message) != std::string::npos);
    CHECK(!fs::exists(d.path / "out"));
  }
  const auto both = loam_test::run_yaml(
      d.path, block("loads:\n  - {type: traction, body: block, face: y+, traction: [0, -1000], "
                    "ramp_time: 1, time_function: {type: linear_ramp, duration: 1}}\n"));
  INFO(both.output);
  CHECK(both.exit_code == 2);
  CHECK(both.output.find("loads.0.ramp_time: give either ramp_time or time_function") !=
        std::string::npos);
}

TEST_CASE("a load's time function reaches the particles: the impulse of a triangular pulse",
          "[time_function][load]") {
  // A free block (no gravity, no boundaries): internal forces cancel, so its momentum is the
  // traction's impulse F sum_k f(t_k) dt (the load acts at each step's start time t_k), with
  // F = t_y A = -1000 Pa x 0.5 m. Fixed dt = 1e-4 s over the pulse 0 -> 1 at 0.003 s -> 0 at
  // 0.005 s, and 20 steps beyond. Tolerance 1e-9 relative (test_plugins_applied.cpp's).
  for (const char* at : {"particle", "surface"}) {
    auto sim = loam_test::make_simulation<2>(block(
        std::string("loads:\n  - {type: traction, body: block, face: y+, traction: [0, "
                    "-1000], apply_at: ") +
        at + ", time_function: {type: triangular_pulse, peak_time: 0.003, end_time: 0.005}}\n"));
    const double dt = 1e-4;
    double impulse = 0;
    for (int k = 0; k < 70; ++k) {
      const double t = sim->time;
      impulse += (t < 0.003 ? t / 0.003 : t < 0.005 ? (0.005 - t) / 0.002 : 0.0) * dt;
      REQUIRE(sim->advance(dt));
    }
    const double expected = -1000 * 0.5 * impulse;
    const auto e = sim->energies();
    std::printf(
        "triangular pulse on a free block, apply_at %-8s: momentum %.12e, F sum f dt = "
        "%.12e (the pulse's area F 0.0025 s = %.3e)\n",
        at, e.momentum[1], expected, -1000 * 0.5 * 0.0025);
    CHECK(e.momentum[1] == Approx(expected).epsilon(1e-9));
    CHECK(std::fabs(e.momentum[0]) <= 1e-9 * std::fabs(expected));
  }
  // ramp_time is the linear ramp, bitwise.
  auto momentum_with = [](const std::string& timing) {
    auto sim = loam_test::make_simulation<2>(
        block("loads:\n  - {type: traction, body: block, face: y+, traction: [0, -1000], " +
              timing + "}\n"));
    for (int k = 0; k < 50; ++k) REQUIRE(sim->advance(1e-4));
    return sim->energies().momentum[1];
  };
  const double a = momentum_with("ramp_time: 0.003");
  const double b = momentum_with("time_function: {type: linear_ramp, duration: 0.003}");
  std::printf("ramp_time 0.003 s: momentum %.17g; linear_ramp: %.17g\n", a, b);
  CHECK(a == b);
}

TEST_CASE("time functions: integrals exact for piecewise-linear functions and the sine",
          "[time_function]") {
  // TimeFunction::integral over [t0, t1]: trapezoids between the kinks (exact for piecewise-
  // linear functions), the sine in closed form. Against the areas by hand, and against a
  // composite Simpson rule with 2e5 intervals (error ~1e-16 relative for these): tolerance 1e-12.
  auto simpson = [](const loam::TimeFunction<2>& f, double a, double b) {
    const int n = 200000;
    const double h = (b - a) / n;
    double s = f.value(a) + f.value(b);
    for (int k = 1; k < n; ++k) s += (k % 2 ? 4 : 2) * f.value(a + k * h);
    return s * h / 3;
  };
  auto pulse = make(
      "{type: triangular_pulse, start: 0.01, peak_time: 0.017, end_time: 0.034, "
      "peak: 2.5}");
  CHECK(pulse->integral(0, 1) == Approx(2.5 * 0.024 / 2).epsilon(1e-14));
  CHECK(pulse->integral(0.02, 0.03) == Approx(simpson(*pulse, 0.02, 0.03)).epsilon(1e-12));
  auto ramp = make("{type: linear_ramp, duration: 2, start: 1, from: 4, to: 2}");
  CHECK(ramp->integral(0, 5) == Approx(4.0 + (4 + 2) / 2.0 * 2 + 2 * 2).epsilon(1e-14));
  auto table = make("{type: table, times: [0, 1, 3, 4], values: [0, 2, 2, -1]}");
  CHECK(table->integral(-1, 5) == Approx(0 + 1 + 4 + 0.5 - 1).epsilon(1e-14));
  CHECK(table->integral(0.5, 3.5) == Approx(simpson(*table, 0.5, 3.5)).epsilon(1e-12));
  auto sine = make("{type: sine, amplitude: 2, frequency: 3, phase: 30, offset: 0.5}");
  const double num = simpson(*sine, 0.1, 0.7), exact = sine->integral(0.1, 0.7);
  std::printf("sine integral over [0.1, 0.7]: closed form %.15g, Simpson %.15g\n", exact, num);
  CHECK(exact == Approx(num).epsilon(1e-12));
  auto c = make("{type: constant, value: 2.5}");
  CHECK(c->integral(1, 3) == 5.0);
}
