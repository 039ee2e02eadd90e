// Building a Simulation<D> from a validated config: grid, plugins, particle sets, bodies generated
// into their sets, initial fields, plugin set-up and the checks of the model before the first step
// (every error at once). The runtime services are in simulation.cpp.
#include "simulation.hpp"

#include <spdlog/spdlog.h>

#include <cmath>

#include "body_lattice.hpp"
#include "registry.hpp"

namespace loam {

namespace {

/// More steps than this at the first stable time step is almost surely a unit slip (a warning;
/// time.max_steps is the hard limit): 1e7 steps of a 10^4-particle model take hours.
constexpr double kPlausibleSteps = 1e7;

/// A face a periodic condition joins to its opposite (Boundary::periodic_axis) must not be held
/// by another condition of the same list: the particles would both wrap and stop there.
template <int D>
void check_periodic_faces(const std::vector<std::unique_ptr<Boundary<D>>>& list,
                          const std::vector<Params>& params, Diagnostics& diag) {
  for (size_t i = 0; i < list.size() && i < params.size(); ++i) {
    const int a = list[i]->periodic_axis();
    if (a < 0) continue;
    for (size_t j = 0; j < list.size(); ++j)
      for (int ph = 0; ph < 2 && j != i; ++ph) {
        const int f = list[j]->holds_face(ph);
        if (f == 2 * a || f == 2 * a + 1) {
          diag.error(params[i].where(), params[i].path(),
                     "another condition (" + params[j].path() + ") holds face " +
                         face_names()[size_t(f)] +
                         ", which this periodic condition joins to its opposite face");
          ph = 2;
        }
      }
  }
}

/// Register each mechanical condition of a list under its reaction's name (`name`, else
/// <type>_<face>, or <type>_<position> for a box), a rigid body under contact also in `rigid`;
/// a name given twice in one list is a located error (its two forces would share a column).
template <int D>
void name_reactions(const std::vector<std::unique_ptr<Boundary<D>>>& list,
                    const std::vector<Params>& params, Reactions<D>& reactions,
                    RigidRecords<D>& rigid, Diagnostics& diag) {
  std::vector<std::string> names;
  for (size_t i = 0; i < list.size() && i < params.size(); ++i) {
    if (!list[i]->reaction_nodes()) continue;
    const Params& p = params[i];
    const std::string name = p.has("name")   ? p.text("name")
                             : p.has("face") ? p.type() + "_" + p.text("face")
                                             : p.type() + "_" + std::to_string(i);
    if (std::find(names.begin(), names.end(), name) != names.end()) {
      const std::string why = "another condition of this list reports its reaction as '" + name +
                              "': give each a distinct name";
      if (p.has("name"))
        diag.error(p.where("name"), p.path("name"), why);
      else
        diag.error(p.where(), p.path(), why);
    }
    names.push_back(name);
    reactions.add(list[i].get(), name);
    if (list[i]->rigid_motion()) rigid.add(list[i].get(), name);
  }
}

}  // namespace

/// gravity, time, numerics and the named selections of the run file.
template <int D>
void Simulation<D>::read_settings() {
  const auto& g = config.vec("gravity");
  for (int d = 0; d < D; ++d) gravity[size_t(d)] = g[size_t(d)];
  const Params& t = config.section("time");
  end_time = t.has("end") ? t.real("end") : 0.0;  // with stages: their sum (create_stages)
  cfl = t.real("cfl");
  fixed_dt = t.has("dt") ? t.real("dt") : 0.0;
  max_steps = long(t.integer("max_steps"));
  const Params& num = config.section("numerics");
  sort_every = int(num.integer("sort_every"));
  check_every = long(num.integer("check_every"));
  keep_last_good = num.flag("keep_last_good");
  ledger.enabled = config.section("output").flag("energy_balance");
  mass_tolerance = num.real("mass_tolerance");
  for (const auto& s : config.list("selections")) {
    Vec lo{}, hi{};
    for (int d = 0; d < D; ++d)
      lo[size_t(d)] = s.vec("min")[size_t(d)], hi[size_t(d)] = s.vec("max")[size_t(d)];
    selections_.push_back({s.text("name"), {lo, hi}});
  }
}

template <int D>
void Simulation<D>::check_step_budget(Diagnostics& diag) {
  const Params& t = config.section("time");
  // Step budget: a stiff set-up (e.g. K_w / n with a porosity near 0) can make the stable time
  // step so small that the run would never finish; say so before writing anything.
  const double dt0 = stable_dt();
  if (end_time / dt0 > double(max_steps))
    diag.error(t.where("end"), t.path("end"),
               "the stable time step at the start is " + format_number(dt0) + " s, so " +
                   format_number(end_time) + " s needs about " +
                   format_number(std::ceil(end_time / dt0)) +
                   " steps, more than time.max_steps = " + std::to_string(max_steps) +
                   " (a stiff material or pore fluid, e.g. K_w / n with a tiny porosity, or a "
                   "fine grid); raise time.max_steps if this is intended");
  else if (end_time / dt0 > kPlausibleSteps)
    diag.warning(t.where("end"), t.path("end"),
                 "the stable time step at the start is " + format_number(dt0) + " s, so " +
                     format_number(end_time) + " s needs about " +
                     format_number(std::ceil(end_time / dt0)) +
                     " steps: a modulus or bulk modulus in Pa meant in kPa, a density in t/m^3, "
                     "or cells smaller than meant? (list time.end under accept_warnings: if it "
                     "is meant)");
}

template <int D>
Simulation<D>::Simulation(const Params& cfg, int num_threads, Diagnostics& diag) : config(cfg) {
  threads = std::max(1, num_threads);
  // Parallel loops without an explicit num_threads (e.g. in plugins) follow --threads too.
  omp_set_num_threads(threads);
  build_grid(config.section("grid"), diag);
  if (!diag.ok()) return;
  read_settings();
  // From here on, keep checking after an error wherever the rest does not depend on it, so that
  // one run reports every problem at once.
  create_plugins(diag);
  create_stages(diag);
  create_sets(diag);
  split_over_ranks(diag);
  const size_t errors_before = diag.errors().size();
  generate_bodies(diag);
  const bool particles_ok = diag.errors().size() == errors_before;
  if (!particles_ok)
    for (auto& s : sets) s.particles.resize(0);  // check the remaining set-up on an empty model
  // Plugins see the generated particles in set-up (e.g. to select faces or request fields).
  shape->setup(*this, diag);
  if (contact && !scheme->supports_contact())
    diag.error(config.section("contact").where(), "contact",
               "scheme '" + config.section("scheme").type() +
                   "' has one velocity field per phase: contact between bodies needs a scheme "
                   "that gives each body its own (docs/contact.md)");
  scheme->setup(*this, diag);
  for (size_t m = 0; m < materials.size(); ++m) materials[m]->setup(*this, int(m), diag);
  setup_stage_plugins("materials", diag);
  if (particles_ok) initialize_fields(diag);
  bool particle_loads = false;
  for (auto& l : loads) particle_loads = particle_loads || l->uses_particle_forces();
  for (auto& st : stages)
    for (auto& l : st.loads) particle_loads = particle_loads || l->uses_particle_forces();
  if (particle_loads)
    external_force = request_field(
        {"external_force", D, "N", "applied external force", Particles<D>::axis_names()});
  sort();
  for (auto& s : sets)
    for (size_t m = 0; m < materials.size(); ++m) {
      const auto& r = s.partition.material_ranges[m];
      if (r.end > r.begin) materials[m]->initialize(s.particles, r.begin, r.end);
    }
  if (particles_ok) scheme->initial_state(*this);
  // Loads select their particles on the model as generated, the bodies that wait for a stage
  // included (the tailings on a dam raise that a later stage activates); when applied they skip
  // the particles not in the run.
  if (particles_ok) {
    for (auto& l : loads) l->setup(*this, diag);
    setup_stage_plugins("loads", diag);
    keep_inactive_bodies_aside();
  }
  for (auto& b : boundaries) b->setup(*this, diag);
  setup_stage_plugins("boundaries", diag);
  check_periodic_faces(boundaries, config.list("boundaries"), diag);
  for (size_t k = 0; k < stages.size(); ++k)
    if (stages[k].sets_boundaries)
      check_periodic_faces(stages[k].boundaries, stages[k].params.list("boundaries"), diag);
  name_reactions(boundaries, config.list("boundaries"), reactions, rigid_records, diag);
  for (size_t k = 0; k < stages.size(); ++k)
    if (stages[k].sets_boundaries)
      name_reactions(stages[k].boundaries, stages[k].params.list("boundaries"), reactions,
                     rigid_records, diag);
  held_faces = HeldFaces<D>(grid, boundaries);
  held_faces_water = HeldFaces<D>(grid, boundaries, 1);
  model_checked = true;
  if (!particles_ok) return;  // sources, sinks and references select particles
  for (auto& p : sources) p->setup(*this, diag);
  for (auto& p : sinks) p->setup(*this, diag);
  if (diag.ok()) check_sources_and_sinks(diag);
  if (reference) reference->setup(*this, diag);
  if (!diag.ok()) return;
  // The sources act at t = 0 too (an inlet starts filled); their particles count as created.
  initial_mass = total_mass();
  for (auto& p : sources) p->apply(*this, time);
  for (auto& s : sets)
    if (s.resized) sort(s);
  double v2 = 0;
  for (const auto& s : sets)
    for (int d = 0; d < D; ++d) {
      const double* v = s.particles.col(s.particles.velocity, d);
      for (size_t i = 0; i < s.size(); ++i) v2 = std::max(v2, v[i] * v[i]);
    }
  max_speed = ranks->max(std::sqrt(v2));  // over the ranks, as after every step (advance)
  check_step_budget(diag);
}

template <int D>
void Simulation<D>::create_sets(Diagnostics& diag) {
  for (const auto& decl : scheme->particle_sets()) {
    sets.emplace_back();
    sets.back().name = decl.name;
  }
  const auto& bl = config.list("bodies");
  for (size_t b = 0; b < bl.size(); ++b) {
    const int s = set_param(bl[b], "set", diag);
    body_set_.push_back(std::max(s, 0));
    if (s >= 0) sets[size_t(s)].bodies.push_back(int(b));
  }
}

template <int D>
void Simulation<D>::build_grid(const Params& g, Diagnostics& diag) {
  Vec o{}, e{}, h{};
  for (int d = 0; d < D; ++d) {
    o[size_t(d)] = g.vec("origin")[size_t(d)];
    e[size_t(d)] = g.vec("extent")[size_t(d)];
    h[size_t(d)] = g.vec("cell_size")[size_t(d)];
    double ratio = e[size_t(d)] / h[size_t(d)];
    const char* axis = "xyz" + d;
    if (ratio < 1 - 1e-6) {  // not even one whole cell
      diag.error(g.where("cell_size"), g.path("cell_size"),
                 std::string("the grid has zero cells along ") + axis[0] + " (extent " +
                     format_number(e[size_t(d)]) + " m < cell_size " + format_number(h[size_t(d)]) +
                     " m)");
    } else if (std::fabs(ratio - std::round(ratio)) > 1e-6 * ratio) {
      spdlog::warn(
          "grid: extent along {} is not a multiple of cell_size; using {} cells of {:.6g} m",
          axis[0], std::lround(ratio), e[size_t(d)] / double(std::lround(ratio)));
    }
  }
  if (diag.ok()) grid.init(o, e, h);
}

template <int D>
void Simulation<D>::create_plugins(Diagnostics& diag) {
  Registry& reg = Registry::instance();
  shape = reg.create<ShapeFunction, D>(config.section("shape_function"));
  scheme = reg.create<Scheme, D>(config.section("scheme"));
  for (const auto& b : config.list("boundaries")) boundaries.push_back(reg.create<Boundary, D>(b));
  for (const auto& l : config.list("loads")) loads.push_back(reg.create<Load, D>(l));
  for (const auto& p : config.list("sources")) sources.push_back(reg.create<Source, D>(p));
  for (const auto& p : config.list("sinks")) sinks.push_back(reg.create<Sink, D>(p));
  if (config.has("damping")) damping = reg.create<Damping, D>(config.section("damping"));
  if (config.has("contact")) contact = reg.create<Contact, D>(config.section("contact"));
  if (config.has("verify")) reference = reg.create<Reference, D>(config.section("verify"));
  const auto& bl = config.list("bodies");
  for (size_t i = 0; i < bl.size(); ++i) {
    for (size_t j = 0; j < i; ++j)
      if (bl[j].text("name") == bl[i].text("name"))
        diag.error(bl[i].where("name"), bl[i].path("name"),
                   "duplicate body name '" + bl[i].text("name") + "'");
    materials.push_back(reg.create<Material, D>(bl[i].section("material")));
  }
}

template <int D>
void Simulation<D>::split_over_ranks(Diagnostics& diag) {
  if (!ranks->distributed()) return;
  // What runs on ranks so far (docs/parallel.md); everything else is refused where it is given.
  const std::string only = " does not run under mpirun yet (docs/parallel.md lists what does)";
  auto refuse_plugin = [&](bool runs, const Params& p) {
    if (!runs) diag.error(p.where(), p.path(), "'" + p.type() + "'" + only);
  };
  // The i-th plugin of a list against the i-th entry of its key (when `given`).
  auto refuse_each = [&](const auto& plugins, const auto& entries, bool given = true) {
    for (size_t i = 0; given && i < plugins.size() && i < entries.size(); ++i)
      refuse_plugin(plugins[i]->runs_on_ranks(), entries[i]);
  };
  if (scheme) refuse_plugin(scheme->runs_on_ranks(), config.section("scheme"));
  if (shape) refuse_plugin(shape->runs_on_ranks(), config.section("shape_function"));
  if (damping && config.given("damping"))
    refuse_plugin(damping->runs_on_ranks(), config.section("damping"));
  refuse_each(boundaries, config.list("boundaries"));
  refuse_each(loads, config.list("loads"));
  refuse_each(sources, config.list("sources"));
  refuse_each(sinks, config.list("sinks"));
  // A stage's own loads, boundaries and damping (swapped in when it begins).
  const auto& sp = config.list("stages");
  for (size_t k = 0; k < stages.size() && k < sp.size(); ++k) {
    const Stage<D>& st = stages[k];
    refuse_each(st.loads, sp[k].list("loads"), st.sets_loads);
    refuse_each(st.boundaries, sp[k].list("boundaries"), st.sets_boundaries);
    if (st.sets_damping && st.damping && sp[k].given("damping"))
      refuse_plugin(st.damping->runs_on_ranks(), sp[k].section("damping"));
  }
  if (reference && config.given("verify"))
    refuse_plugin(reference->runs_on_ranks(), config.section("verify"));
  if (!shape || !diag.ok()) return;
  // A periodic axis stays whole on every rank (its faces are joined node by node).
  std::array<bool, D> whole{};
  auto keep_periodic_whole = [&](const auto& list) {
    for (const auto& b : list)
      if (b->periodic_axis() >= 0 && b->periodic_axis() < D)
        whole[size_t(b->periodic_axis())] = true;
  };
  keep_periodic_whole(boundaries);
  for (const Stage<D>& st : stages) keep_periodic_whole(st.boundaries);
  const std::string why =
      ranks->decompose(grid, shape->rows_below(), shape->rows_above(), threads, whole);
  if (!why.empty()) diag.error(config.section("grid").where(), "grid", why);
}

template <int D>
void Simulation<D>::generate_bodies(Diagnostics& diag) {
  GeneratedPoints points;
  if (!generate_points(points, diag)) return;
  fill_sets(points);
  set_initial_velocity_and_stress(points);
}

/// The particles this rank keeps (all of them serially): position, body, volume and id. Each
/// rank generates only the points of its own cells (walk_body_lattice); the ids (numbered over
/// all bodies in lattice order) and the bodies' bounding boxes are those of the serial run.
template <int D>
struct Simulation<D>::GeneratedPoints {
  std::vector<Vec> x;
  std::vector<uint16_t> owner;
  std::vector<double> volume;
  std::vector<size_t> id;
  std::vector<size_t> first_kept;  // per body, its first point here
};

template <int D>
bool Simulation<D>::generate_points(GeneratedPoints& pts, Diagnostics& diag) {
  Registry& reg = Registry::instance();
  const auto& bl = config.list("bodies");
  const size_t errors_before = diag.errors().size();
  auto& [xs, owner, vols, ids, first_kept] = pts;
  size_t next_id = 0;
  for (size_t b = 0; b < bl.size(); ++b) {
    first_kept.push_back(xs.size());
    const Params& bp = bl[b];
    if (!bp.has("generator")) {  // starts empty: its particles come from a source
      Body body;
      body.name = bp.text("name");
      body.params = bp;
      body.first_id = next_id;
      body.lower.assign(D, 0.0);
      body.upper.assign(D, 0.0);
      for (int d = 0; d < D; ++d)
        body.spacing.push_back(grid.cell[size_t(d)] / double(bp.integer("particles_per_cell")));
      bodies.push_back(std::move(body));
      continue;
    }
    auto gen = reg.create<Generator, D>(bp.section("generator"));
    if (std::string problem = gen->check(); !problem.empty()) {
      diag.error(bp.where("generator"), bp.path("generator"), problem);
      continue;
    }
    const Vec lo = gen->lower(), hi = gen->upper();
    if (!grid.holds_box(lo, hi)) {
      diag.error(bp.where("generator"), bp.path("generator"),
                 "particles outside the grid: the body spans " + format_box(lo, hi) +
                     " but the grid spans " + format_box(grid.origin, grid.upper_corner()));
      continue;
    }
    const int ppc = int(bp.integer("particles_per_cell"));
    Body body;
    body.name = bp.text("name");
    body.params = bp;
    body.first_id = next_id;
    Vec s{};
    double vol = 1;
    std::array<long, D> i0{}, i1{};
    for (int d = 0; d < D; ++d) {
      s[size_t(d)] = grid.cell[size_t(d)] / ppc;
      vol *= s[size_t(d)];
      // Lattice points origin + (i + 1/2) s inside [lo, hi].
      i0[size_t(d)] =
          long(std::ceil((lo[size_t(d)] - grid.origin[size_t(d)]) / s[size_t(d)] - 0.5 - 1e-9));
      i1[size_t(d)] =
          long(std::floor((hi[size_t(d)] - grid.origin[size_t(d)]) / s[size_t(d)] - 0.5 + 1e-9));
    }
    const BodyLattice<D> lattice = walk_body_lattice<D>(grid, *ranks, *gen, ppc, s, i0, i1);
    for (size_t p = 0; p < lattice.x.size(); ++p) {
      xs.push_back(lattice.x[p]);
      owner.push_back(uint16_t(b));
      vols.push_back(vol);
      ids.push_back(next_id + lattice.number[p]);
    }
    next_id += lattice.count;
    body.count = lattice.count;
    body.local_count = lattice.x.size();
    if (body.count == 0) {
      diag.error(bp.where("generator"), bp.path("generator"),
                 "the generator produced no particles (region smaller than the particle spacing " +
                     format_number(s[0]) + " m?)");
      continue;
    }
    body.lower.assign(lattice.lower.begin(), lattice.lower.end());
    body.upper.assign(lattice.upper.begin(), lattice.upper.end());
    body.spacing.assign(s.begin(), s.end());
    bodies.push_back(std::move(body));
  }
  if (diag.errors().size() != errors_before) return false;
  if (next_id > size_t(UINT32_MAX)) {
    diag.error(config.where("bodies"), "bodies", "more than 2^32 particles");
    return false;
  }
  // A source's particles are numbered after every generated one (those of the bodies that wait
  // for a stage included), over all ranks.
  next_id_ = uint32_t(next_id);
  return true;
}

/// Each set holds its bodies' particles in body order; ids count over all bodies.
template <int D>
void Simulation<D>::fill_sets(const GeneratedPoints& pts) {
  const auto& [xs, owner, vols, ids, first_kept] = pts;
  for (auto& body : bodies) body.set = body_set_[size_t(&body - bodies.data())];
  for (size_t si = 0; si < sets.size(); ++si) {
    Particles<D>& P = sets[si].particles;
    size_t n = 0;
    for (auto& body : bodies)
      if (body.set == int(si)) body.first_index = n, n += body.local_count;
    P.resize(n);
    for (size_t b = 0; b < bodies.size(); ++b) {
      const Body& body = bodies[b];
      if (body.set != int(si)) continue;
      for (size_t k = 0; k < body.local_count; ++k) {
        const size_t i = body.first_index + k, g = first_kept[b] + k;
        P.id[i] = uint32_t(ids[g]);
        P.material[i] = owner[g];
        P.body[i] = owner[g];
        for (int d = 0; d < D; ++d) P.col(P.position, d)[i] = xs[g][size_t(d)];
        P.col(P.volume)[i] = vols[g];
        P.col(P.mass)[i] = vols[g] * materials[owner[g]]->density();
      }
    }
    sets[si].invalidate_index();
  }
}

/// The bodies' `velocity:` and `stress:` fields at their particles' positions.
template <int D>
void Simulation<D>::set_initial_velocity_and_stress(const GeneratedPoints& pts) {
  Registry& reg = Registry::instance();
  const auto& bl = config.list("bodies");
  std::vector<double> value(size_t(Particles<D>::NS));
  for (size_t b = 0; b < bl.size(); ++b) {
    const Params& bp = bl[b];
    Particles<D>& P = sets[size_t(bodies[b].set)].particles;
    for (auto [key, field] : {std::pair<const char*, int>{"velocity", P.velocity},
                              std::pair<const char*, int>{"stress", P.stress}}) {
      if (!bp.has(key)) continue;
      auto f = reg.create<Field, D>(bp.section(key));
      const int nc = P.info(field).components;
      for (size_t k = 0; k < bodies[b].local_count; ++k) {
        f->value(pts.x[pts.first_kept[b] + k], value.data());
        for (int c = 0; c < nc; ++c) P.col(field, c)[bodies[b].first_index + k] = value[size_t(c)];
      }
    }
  }
}

template <int D>
void Simulation<D>::initialize_fields(Diagnostics& diag) {
  // Before the first sort a body's particles are one index range of its set.
  const auto& bl = config.list("bodies");
  for (size_t b = 0; b < bl.size() && b < bodies.size(); ++b)
    for (const Params& e : bl[b].list("initial")) {
      Particles<D>& particles = sets[size_t(bodies[b].set)].particles;
      const std::string name = e.text("field");
      const int h = particles.has(particles.find(name)) ? particles.find(name) : -1;
      // Scalar: one component without component names (1D vectors have one component too).
      auto scalar = [&](int k) {
        return particles.info(k).components == 1 && particles.info(k).component_names.empty();
      };
      if (h < 0 || !scalar(h)) {
        std::vector<std::string> scalars;
        for (int k = 0; k < particles.num_fields(); ++k)
          if (particles.has(k) && scalar(k)) scalars.push_back(particles.info(k).name);
        diag.error(e.where("field"), e.path("field"),
                   (h < 0 ? "no particle field '" : "'") + name +
                       (h < 0 ? "'" : "' is not a scalar field") +
                       " in this run; scalar fields: " + join(scalars, ", "));
        continue;
      }
      auto f = Registry::instance().create<Field, D>(e.section("value"));
      std::array<double, D> x{};
      for (size_t i = bodies[b].first_index; i < bodies[b].first_index + bodies[b].local_count;
           ++i) {
        for (int d = 0; d < D; ++d) x[size_t(d)] = particles.col(particles.position, d)[i];
        f->value(x, particles.col(h) + i);
      }
    }
}

template <int D>
void Simulation<D>::check_sources_and_sinks(Diagnostics& diag) {
  const auto& sp = config.list("sources");
  const auto& kp = config.list("sinks");
  for (size_t i = 0; i < sources.size(); ++i) {
    Vec lo{}, hi{};
    sources[i]->region(lo, hi);
    for (size_t k = 0; k < sinks.size(); ++k)
      if (sinks[k]->overlaps(lo, hi))
        diag.error(kp[k].where(), kp[k].path(),
                   "the sink overlaps the region of " + sp[i].path() +
                       ": it would remove the particles the source creates");
  }
}

// The class is instantiated once, in simulation.cpp (`template class`); the constructor is defined
// here, so it is instantiated here (the private helpers above with it).
template Simulation<1>::Simulation(const Params&, int, Diagnostics&);
template Simulation<2>::Simulation(const Params&, int, Diagnostics&);
template Simulation<3>::Simulation(const Params&, int, Diagnostics&);

}  // namespace loam
