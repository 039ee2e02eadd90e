// The schema of a run file: every key, its type, unit, range and documentation, from which the
// validation, `loam schema` and docs/config.md come (the plugins' own keys are their schemas).
#include <string>
#include <utility>

#include "config.hpp"
#include "particles.hpp"
#include "registry.hpp"

namespace loam {

// GCC 12 at -O3 reports a false -Wrestrict in the std::string operator+ inlined in these schema
// builders (as in schema.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wrestrict"

namespace {

/// One entry of `stages:` (docs/stages.md). Its changes act at the stage's start; a key that is
/// absent leaves that part of the model as the previous stage had it.
Schema stage_schema() {
  Schema st;
  st.text("name", "stage name (summary.json stages[], messages)").required();
  st.real("duration", "s", "simulated time of the stage").positive();
  st.choice("until", {"static"},
            "static: the stage ends once the model is at rest (every particle moving slower "
            "than static_speed for static_window), or after max_time as not static");
  st.real("max_time", "s", "with until: static, the time after which the stage ends as not static")
      .positive();
  st.real("static_speed", "m/s",
          "with until: static: the model is at rest while every particle moves slower than "
          "this, |x(n+1) - x(n)| / dt (it bounds the kinetic energy of the motion: E_k <= M v^2 "
          "/ 2)")
      .def("1e-5")
      .positive();
  st.real("static_window", "s",
          "with until: static: how long the speeds must stay below static_speed (0: the time a "
          "P-wave takes to cross the grid's longest side at the stage's start)")
      .def("0")
      .min(0);
  st.choice("if_not_static", {"stop", "continue"},
            "what follows a stage that did not reach static: stop the run there (its record says "
            "so; the remaining stages are listed as not run) or go on")
      .def("stop");
  st.plugin_list("loads", "load",
                 "the loads from this stage on, replacing the previous stage's (an empty list "
                 "removes them all); their time (ramp_time) counts from the stage's start");
  st.plugin_list("boundaries", "boundary",
                 "the boundary conditions from this stage on, replacing the previous ones");
  st.plugin("damping", "damping",
            "damping from this stage on (`none` switches it off); absent: unchanged");
  {
    Schema m;
    m.text("body", "the body whose material changes").required();
    m.plugin("material", "material",
             "its material from this stage on: the keys given replace the body's current ones "
             "(checked by the material's schema); with another `type:`, the whole material")
        .required();
    st.section_list("materials", m,
                    "material changes at the stage's start (e.g. phi 42 -> 28 deg, or elastic "
                    "during a gravity stage and Mohr-Coulomb after it)");
  }
  st.string_list("activate",
                 "bodies whose particles join the run at the stage's start (construction: a body "
                 "with `active: false`, its initial stress from its `stress:`)")
      .def("[]");
  st.string_list("deactivate",
                 "bodies whose particles leave the run at the stage's start (excavation)")
      .def("[]");
  st.string_list(
        "reset",
        "what is reset at the stage's start: displacement (the reference of the "
        "displacement output and of max_displacement becomes the current position), "
        "velocity (every phase), plastic_strain (the output plastic_strain_eq; no material "
        "state: a softened material stays softened)")
      .def("[]");
  {
    Schema o;
    o.integer("every_steps", "write a frame every N steps").min(1);
    o.real("every_time", "s", "write a frame every T seconds of simulated time").positive();
    st.section("output", o, "frame interval from this stage on (absent: unchanged)");
  }
  st.check([](const Params& p, Diagnostics& d) {
    const bool until = p.has("until");
    if (until == p.has("duration"))
      d.error(p.where(), p.path(), "give exactly one of 'duration' or 'until: static'");
    if (until && !p.has("max_time"))
      d.error(p.where("until"), p.path("until"),
              "until: static needs max_time (the time after which the stage counts as not "
              "static)");
    if (!until && p.has("max_time"))
      d.error(p.where("max_time"), p.path("max_time"), "max_time belongs to until: static");
    const std::vector<std::string> resets{"displacement", "velocity", "plastic_strain"};
    const auto& r = p.strings("reset");
    for (size_t i = 0; i < r.size(); ++i)
      if (std::find(resets.begin(), resets.end(), r[i]) == resets.end())
        d.error(p.where("reset", i), p.path("reset") + "." + std::to_string(i),
                "unknown reset '" + r[i] + "'" + suggest(r[i], resets, "valid values are"));
  });
  return st;
}

/// `strength_reduction:` (docs/strength_reduction.md): after the stages, the factor of safety by
/// bisection on the strength reduction factor F, each trial from the last stage's static state.
Schema strength_reduction_schema() {
  Schema r;
  r.vector("factors", "-",
           "[F_low, F_high]: the bracket the factor of safety is searched in; F_low must leave "
           "the model static and F_high must not (both are tried first)",
           2)
      .positive();
  r.real("tolerance", "-", "the search ends when the bracket is this narrow (absolute, in F)")
      .def("0.01")
      .positive();
  r.string_list("bodies",
                "the bodies whose strength is reduced (default: every body whose material has a "
                "strength: Material::reduced)")
      .def("[]");
  r.real("max_time", "s",
         "the longest simulated time a trial may take: one neither static nor moved "
         "failure_displacement by then is undecided (counted as failed; the search's status is "
         "undecided when such a trial bounds the bracket)")
      .positive();
  r.real("static_speed", "m/s",
         "a trial is static once every particle moves slower than this for static_window "
         "(|x(n+1) - x(n)| / dt, as for a stage with until: static)")
      .def("1e-5")
      .positive();
  r.real("static_window", "s",
         "how long the speeds must stay below static_speed (0: the time a P-wave takes to cross "
         "the grid's longest side)")
      .def("0")
      .min(0);
  r.real("failure_displacement", "m",
         "a trial has failed when a particle has moved this far from the static state (along a "
         "periodic axis the nearest image)")
      .positive();
  r.check([](const Params& p, Diagnostics& d) {
    if (!p.has("factors")) return;
    const auto& f = p.vec("factors");
    if (f.size() == 2 && f[1] <= f[0])
      d.error(p.where("factors"), p.path("factors"),
              "factors = [" + format_number(f[0]) + ", " + format_number(f[1]) +
                  "]: F_high must exceed F_low");
  });
  return r;
}

/// `grid:`: the background grid.
Schema grid_schema() {
  Schema g;
  g.vector("origin", "m", "lower corner of the grid").def("0").scalar_ok();
  g.vector("extent", "m",
           "size of the grid along each axis; its length sets the dimension (1, 2 or 3)")
      .required()
      .positive();
  g.vector("cell_size", "m",
           "cell size (one number or one per axis); the extent must be a multiple")
      .required()
      .positive()
      .scalar_ok();
  return g;
}

/// One entry of `bodies:`.
Schema body_schema() {
  Schema b;
  b.text("name", "body name, used by loads, references and output").required();
  b.text("set",
         "the particle set of the scheme the body's particles belong to (default: the "
         "scheme's first set; `loam plugins` lists each scheme's sets)");
  b.plugin("generator", "generator",
           "region filled with particles at t = 0 (none: the body starts empty and gets its "
           "particles from a source)");
  b.integer("particles_per_cell", "particles per cell along each axis").def("2").min(1).max(10);
  b.plugin("material", "material", "constitutive model of the body").required();
  b.boolean("active",
            "false: the body's particles are generated but join the run only when a stage "
            "activates it (construction)")
      .def("true");
  b.plugin("velocity", "field", "initial velocity (a list is a constant)").components(kDimension);
  b.plugin("stress", "field", "initial Cauchy stress, Voigt xx yy zz xy yz xz (tension positive)")
      .components(-100);  // resolved to the stress component count below
  {
    Schema i;
    i.text("field",
           "a scalar particle field the run has after set-up (e.g. pore_pressure of a "
           "two-phase scheme)")
        .required();
    i.plugin("value", "field", "its initial value (a list is a constant)").components(1).required();
    b.section_list("initial", i,
                   "initial values of further scalar particle fields, set after the scheme "
                   "and materials have created them (e.g. a hydrostatic pore pressure)");
  }
  return b;
}

/// One entry of `selections:`.
Schema selection_schema() {
  Schema ps;
  ps.text("name", "selection name, referred to by loads (traction `selection:`)").required();
  ps.vector("min", "m", "lower corner of the selection box").required();
  ps.vector("max", "m", "upper corner of the selection box").required();
  return ps;
}

/// `time:`.
Schema time_schema() {
  Schema t;
  t.real("end", "s", "simulated end time (a run with `stages:` gives each stage's time instead)")
      .positive();
  t.real("cfl", "-", "Courant number: dt = cfl * cell / (wave speed + particle speed)")
      .def("0.5")
      .above(0)
      .max(1);
  t.real("dt", "s", "fixed time step (overrides cfl)").positive();
  t.integer("max_steps",
            "step budget: a run whose first stable time step would need more steps to reach "
            "`end` is rejected before it starts, and a run whose time step collapses stops "
            "when it reaches the budget (exit 3)")
      .def("100000000")
      .min(1);
  t.real("min_dt_ratio", "-",
         "a stable time step below this fraction of the first step's stops the run (exit 3): "
         "the wave or particle speed has exploded (e.g. USL with linear shape functions at a "
         "node of tiny mass), and the run would otherwise crawl until max_steps")
      .def("1e-6")
      .above(0)
      .below(1);
  return t;
}

/// `output:`, with its `checkpoint:`.
Schema output_schema() {
  const Registry& reg = Registry::instance();
  Schema o;
  o.integer("every_steps", "write a frame every N steps").min(1);
  o.real("every_time", "s", "write a frame every T seconds of simulated time").positive();
  o.string_list(
       "fields",
       "particle fields to write besides position (an unknown name lists the available "
       "ones); derived when written: displacement (since the last displacement reset) and "
       "strain_magnitude (sqrt(eps:eps) of the logarithmic strain 1/2 ln(F F^T) since that "
       "reset; it requests the deformation gradient F)")
      .def("[velocity, stress]");
  o.plugin("writer", "writer", "output format").def(reg.default_of("writer"));
  o.integer("history_every",
            "write energies and momentum to history.csv every N steps (0: at frames)")
      .def("0")
      .min(0);
  o.boolean("energy_balance",
            "add the energy balance to history.csv and summary.json: material, damping and "
            "transfer dissipation, the work of loads and boundary conditions, the energy "
            "particles carry in and out, and the balance (docs/energy_balance.md; costs a few "
            "% of the step)")
      .def("false");
  o.integer("history_digits",
            "significant digits of the numbers in history.csv (17: every bit of a double)")
      .def("12")
      .min(6)
      .max(17);
  Schema c;
  c.integer("every_steps", "write a checkpoint every N steps").min(1);
  c.real("every_wall_seconds", "s", "write a checkpoint every T seconds of wall time").positive();
  c.integer("keep", "how many of the newest checkpoints to keep (default 2)").min(1);
  c.check([](const Params& p, Diagnostics& d) {
    if (p.has("keep") && !p.has("every_steps") && !p.has("every_wall_seconds"))
      d.error(p.where(), p.path(), "give every_steps or every_wall_seconds (or both)");
  });
  o.section("checkpoint", c,
            "checkpoints (checkpoint_<step>.h5 in the output directory): loam run --resume "
            "DIR continues from the newest, bit for bit");
  return o;
}

/// One entry of `probes:`.
Schema probe_schema() {
  Schema p;
  p.text("name", "probe name; written to probe_<name>.csv").required();
  p.vector("particle_near", "m", "follow the particle nearest to this point at t = 0");
  p.text("set", "with particle_near: the particle set to search (default: the scheme's first)");
  p.vector("node", "-", "grid node indices (i, j, k)");
  p.vector("node_near", "m", "the grid node nearest to this point");
  p.string_list("fields", "fields to record").def("[position, velocity]");
  p.integer("every_steps", "sample every N steps").def("1").min(1);
  return p;
}

/// `numerics:`.
Schema numerics_schema() {
  Schema n;
  n.integer("sort_every", "sort particles by cell every N steps (locality, thread partition)")
      .def("20")
      .min(1);
  n.real("mass_tolerance", "kg",
         "nodes with less mass get no acceleration (f / m is unbounded there) but keep their "
         "points' mean velocity p / m")
      .def("1e-12")
      .positive();
  n.integer("check_every", "check particles for NaN/inf and leaving the grid every N steps")
      .def("10")
      .min(1);
  n.boolean("keep_last_good",
            "keep a copy of the particles at each passed check, written as the last regular "
            "frame (and, with output.checkpoint, checkpoint) when a later step fails (the "
            "failed state goes to a 'failed' frame); false saves the copy's memory (about the "
            "particles' own)")
      .def("true");
  return n;
}

/// What the run file's keys require of each other: time.end or stages, strength reduction
/// after a static stage.
void check_time_and_stages(const Params& p, Diagnostics& d) {
  const bool staged = !p.list("stages").empty();
  const Params& t = p.section("time");
  if (staged && t.has("end"))
    d.error(t.where("end"), t.path("end"),
            "a run with stages takes its time from them (each stage's duration or max_time): "
            "remove time.end");
  if (!staged && !t.present("end"))
    d.error(t.where(), t.path(), "missing required key 'end' (simulated end time, s)");
  if (p.given("strength_reduction")) {  // its keys are required only when it is given
    const Params& r = p.section("strength_reduction");
    if (!staged || !p.list("stages").back().has("until"))
      d.error(r.where(), r.path(),
              "strength reduction starts from a static state: the last stage must be `until: "
              "static` (e.g. the gravity stage)");
    const std::pair<const char*, const char*> needed[] = {
        {"factors", "[F_low, F_high]"},
        {"max_time", "the time limit of a trial, s"},
        {"failure_displacement", "the displacement at which a trial has failed, m"}};
    for (const auto& [k, what] : needed)
      if (!r.present(k))
        d.error(r.where(), r.path(k),
                std::string("missing required key '") + k + "' (" + what + ")");
  }
}

}  // namespace

Schema config_schema() {
  const Registry& reg = Registry::instance();
  Schema s;
  s.string_list("plugins", "shared libraries with out-of-tree plugins, loaded before validation");
  s.section("grid", grid_schema(), "background grid").required();
  // Defaults are whatever plugin declared itself the default of its kind; the core names none.
  s.plugin("shape_function", "shape_function", "interpolation between particles and nodes")
      .def(reg.default_of("shape_function"));
  s.plugin("scheme", "scheme", "what one explicit step does (mixture formulation, update order)")
      .def(reg.default_of("scheme"));
  s.vector("gravity", "m/s^2", "gravitational acceleration").def("0").scalar_ok();
  s.section_list("bodies", body_schema(), "bodies of particles").required();
  s.section_list("selections", selection_schema(),
                 "named selections of particles (boxes, at t = 0)");
  s.plugin_list("boundaries", "boundary", "boundary conditions on grid faces");
  s.plugin_list("loads", "load", "external loads");
  s.plugin_list("sources", "source", "particle sources: inflow of a body's particles");
  s.plugin_list("sinks", "sink", "particle sinks: outflow, removing particles");
  s.plugin("damping", "damping", "numerical damping (e.g. to reach a static state)");
  s.plugin("contact", "contact",
           "contact between bodies: each body in contact moves on its own velocity field and "
           "the law exchanges momentum where they meet (absent: one velocity field, bodies "
           "stick where they touch)");
  s.section("time", time_schema(), "time integration (with stages: without `end`)");
  s.section("output", output_schema(), "output of particle frames");
  s.section_list("probes", probe_schema(), "time series at a particle or a node, written as CSV");
  s.plugin("verify", "reference", "analytic reference; its error metrics go to summary.json");
  s.section_list("stages", stage_schema(),
                 "a staged analysis (docs/stages.md): the run goes through these stages in order, "
                 "each applying its changes at its start and ending after its duration or once "
                 "static; without it the run is one stage of time.end. A stage with "
                 "repeat: {times: N, step: {key.path: increment}} stands for N copies of it, "
                 "NAME_1 .. NAME_N, each stepped value v + k increment (docs/stages.md, Repeated "
                 "stages)");
  s.section("strength_reduction", strength_reduction_schema(),
            "a factor of safety by strength reduction after the last stage "
            "(docs/strength_reduction.md): c and tan(phi) divided by F, bisection on F, each "
            "trial from the last stage's static state");
  s.check(check_time_and_stages);
  s.section("numerics", numerics_schema(), "numerical controls");
  s.string_list("accept_warnings",
                "key paths (as a warning prints them, e.g. bodies.0.material.E) whose implausible "
                "values are meant: their warnings are not shown");
  return s;
}
#pragma GCC diagnostic pop

}  // namespace loam
