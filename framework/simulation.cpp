#include "simulation.hpp"

#include <spdlog/spdlog.h>

#include <cmath>
#include <sstream>

#include "registry.hpp"

namespace loam {

template <int D>
Simulation<D>::~Simulation() = default;

template <int D>
Simulation<D>::Simulation(const Params& cfg, int num_threads, Diagnostics& diag) : config(cfg) {
  threads = std::max(1, num_threads);
  // Parallel loops without an explicit num_threads (e.g. in plugins) follow --threads too.
  omp_set_num_threads(threads);
  build_grid(config.section("grid"), diag);
  if (!diag.ok()) return;
  const auto& g = config.vec("gravity");
  for (int d = 0; d < D; ++d) gravity[size_t(d)] = g[size_t(d)];
  const Params& t = config.section("time");
  end_time = t.real("end");
  cfl = t.real("cfl");
  fixed_dt = t.has("dt") ? t.real("dt") : 0.0;
  max_steps = long(t.integer("max_steps"));
  const Params& num = config.section("numerics");
  sort_every = int(num.integer("sort_every"));
  mass_tolerance = num.real("mass_tolerance");
  for (const auto& s : config.list("particle_sets")) {
    Vec lo{}, hi{};
    for (int d = 0; d < D; ++d)
      lo[size_t(d)] = s.vec("min")[size_t(d)], hi[size_t(d)] = s.vec("max")[size_t(d)];
    sets_.push_back({s.text("name"), {lo, hi}});
  }
  // From here on, keep checking after an error wherever the rest does not depend on it, so that
  // one run reports every problem at once.
  create_plugins(diag);
  const size_t errors_before = diag.errors().size();
  generate_bodies(diag);
  const bool particles_ok = diag.errors().size() == errors_before;
  if (!particles_ok) particles.resize(0);  // check the remaining set-up on an empty model
  // Plugins see the generated particles in set-up (e.g. to select faces or request fields).
  shape->setup(*this, diag);
  scheme->setup(*this, diag);
  for (size_t m = 0; m < materials.size(); ++m) materials[m]->setup(*this, int(m), diag);
  if (particles_ok) initialize_fields(diag);
  bool particle_loads = false;
  for (auto& l : loads) particle_loads = particle_loads || l->uses_particle_forces();
  if (particle_loads)
    external_force = particles.request(
        {"external_force", D, "N", "applied external force", Particles<D>::axis_names()});
  sort();
  for (size_t m = 0; m < materials.size(); ++m) {
    const auto& r = partition.material_ranges[m];
    if (r.end > r.begin) materials[m]->initialize(particles, r.begin, r.end);
  }
  for (auto& b : boundaries) b->setup(*this, diag);
  held_faces = HeldFaces<D>(grid, boundaries);
  model_checked = true;
  if (!particles_ok) return;  // loads and references select particles
  for (auto& l : loads) l->setup(*this, diag);
  if (reference) reference->setup(*this, diag);
  if (!diag.ok()) return;
  double v2 = 0;
  for (int d = 0; d < D; ++d) {
    const double* v = particles.col(particles.velocity, d);
    for (size_t i = 0; i < particles.size(); ++i) v2 = std::max(v2, v[i] * v[i]);
  }
  max_speed = std::sqrt(v2);
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
  if (config.has("damping")) damping = reg.create<Damping, D>(config.section("damping"));
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
void Simulation<D>::generate_bodies(Diagnostics& diag) {
  Registry& reg = Registry::instance();
  const auto& bl = config.list("bodies");
  const size_t errors_before = diag.errors().size();
  std::vector<Vec> xs;
  std::vector<uint16_t> owner;
  std::vector<double> vols;
  for (size_t b = 0; b < bl.size(); ++b) {
    const Params& bp = bl[b];
    auto gen = reg.create<Generator, D>(bp.section("generator"));
    if (std::string problem = gen->check(); !problem.empty()) {
      diag.error(bp.where("generator"), bp.path("generator"), problem);
      continue;
    }
    Vec lo = gen->lower(), hi = gen->upper();
    bool inside = true;
    for (int d = 0; d < D; ++d)
      inside = inside && lo[size_t(d)] >= grid.origin[size_t(d)] - 1e-12 &&
               hi[size_t(d)] <= grid.upper(d) + 1e-12;
    if (!inside) {
      std::ostringstream s;
      s << "particles outside the grid: the body spans [";
      for (int d = 0; d < D; ++d) s << (d ? ", " : "") << format_number(lo[size_t(d)]);
      s << "] to [";
      for (int d = 0; d < D; ++d) s << (d ? ", " : "") << format_number(hi[size_t(d)]);
      s << "] but the grid spans [";
      for (int d = 0; d < D; ++d) s << (d ? ", " : "") << format_number(grid.origin[size_t(d)]);
      s << "] to [";
      for (int d = 0; d < D; ++d) s << (d ? ", " : "") << format_number(grid.upper(d));
      s << "]";
      diag.error(bp.where("generator"), bp.path("generator"), s.str());
      continue;
    }
    const int ppc = int(bp.integer("particles_per_cell"));
    Body body;
    body.name = bp.text("name");
    body.params = bp;
    body.first_id = xs.size();
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
    std::array<long, D> i = i0;
    bool empty_range = false;
    for (int d = 0; d < D; ++d) empty_range = empty_range || i1[size_t(d)] < i0[size_t(d)];
    Vec plo, phi;
    plo.fill(1e300);
    phi.fill(-1e300);
    while (!empty_range) {
      Vec x{};
      for (int d = 0; d < D; ++d)
        x[size_t(d)] = grid.origin[size_t(d)] + (double(i[size_t(d)]) + 0.5) * s[size_t(d)];
      if (gen->contains(x)) {
        xs.push_back(x);
        owner.push_back(uint16_t(b));
        vols.push_back(vol);
        for (int d = 0; d < D; ++d) {
          plo[size_t(d)] = std::min(plo[size_t(d)], x[size_t(d)] - 0.5 * s[size_t(d)]);
          phi[size_t(d)] = std::max(phi[size_t(d)], x[size_t(d)] + 0.5 * s[size_t(d)]);
        }
      }
      int d = 0;
      while (d < D && ++i[size_t(d)] > i1[size_t(d)]) i[size_t(d)] = i0[size_t(d)], ++d;
      if (d == D) break;
    }
    body.count = xs.size() - body.first_id;
    if (body.count == 0) {
      diag.error(bp.where("generator"), bp.path("generator"),
                 "the generator produced no particles (region smaller than the particle spacing " +
                     format_number(s[0]) + " m?)");
      continue;
    }
    body.lower.assign(plo.begin(), plo.end());
    body.upper.assign(phi.begin(), phi.end());
    body.spacing.assign(s.begin(), s.end());
    bodies.push_back(std::move(body));
  }
  if (diag.errors().size() != errors_before) return;
  const size_t n = xs.size();
  if (n > size_t(UINT32_MAX)) {
    diag.error(config.where("bodies"), "bodies", "more than 2^32 particles");
    return;
  }
  particles.resize(n);
  for (size_t i = 0; i < n; ++i) {
    particles.id[i] = uint32_t(i);
    particles.material[i] = owner[i];
    particles.body[i] = owner[i];
    for (int d = 0; d < D; ++d) particles.col(particles.position, d)[i] = xs[i][size_t(d)];
    particles.col(particles.volume)[i] = vols[i];
    particles.col(particles.mass)[i] = vols[i] * materials[owner[i]]->density();
  }
  // Initial velocity and stress fields.
  std::vector<double> value(size_t(Particles<D>::NS));
  for (size_t b = 0; b < bl.size(); ++b) {
    const Params& bp = bl[b];
    for (auto [key, field] : {std::pair<const char*, int>{"velocity", particles.velocity},
                              std::pair<const char*, int>{"stress", particles.stress}}) {
      if (!bp.has(key)) continue;
      auto f = reg.create<Field, D>(bp.section(key));
      const int nc = particles.info(field).components;
      for (size_t i = bodies[b].first_id; i < bodies[b].first_id + bodies[b].count; ++i) {
        f->value(xs[i], value.data());
        for (int c = 0; c < nc; ++c) particles.col(field, c)[i] = value[size_t(c)];
      }
    }
  }
}

template <int D>
void Simulation<D>::initialize_fields(Diagnostics& diag) {
  // Before the first sort: particle index = id, so a body's particles are its id range.
  const auto& bl = config.list("bodies");
  for (size_t b = 0; b < bl.size() && b < bodies.size(); ++b)
    for (const Params& e : bl[b].list("initial")) {
      const std::string name = e.text("field");
      const int h = particles.find(name);
      // Scalar: one component without component names (1D vectors have one component too).
      auto scalar = [&](int k) {
        return particles.info(k).components == 1 && particles.info(k).component_names.empty();
      };
      if (h < 0 || !scalar(h)) {
        std::vector<std::string> scalars;
        for (int k = 0; k < particles.num_fields(); ++k)
          if (scalar(k)) scalars.push_back(particles.info(k).name);
        diag.error(e.where("field"), e.path("field"),
                   (h < 0 ? "no particle field '" : "'") + name +
                       (h < 0 ? "'" : "' is not a scalar field") +
                       " in this run; scalar fields: " + join(scalars, ", "));
        continue;
      }
      auto f = Registry::instance().create<Field, D>(e.section("value"));
      std::array<double, D> x{};
      for (size_t i = bodies[b].first_id; i < bodies[b].first_id + bodies[b].count; ++i) {
        for (int d = 0; d < D; ++d) x[size_t(d)] = particles.col(particles.position, d)[i];
        f->value(x, particles.col(h) + i);
      }
    }
}

template <int D>
double Simulation<D>::stable_dt() const {
  if (fixed_dt > 0) return fixed_dt;
  double c = 0;
  for (size_t m = 0; m < materials.size(); ++m) {
    const auto& r = partition.material_ranges[m];
    if (r.end > r.begin) c = std::max(c, materials[m]->wave_speed(particles, r.begin, r.end));
  }
  double dt_cfl = cfl * grid.min_cell() / std::max(c + max_speed, 1e-300);
  return std::min(dt_cfl, scheme->stable_dt(*this));
}

template <int D>
void Simulation<D>::prepare_particle_loads() {
  if (external_force < 0) return;
  for (int d = 0; d < D; ++d) {
    double* f = particles.col(external_force, d);
    std::fill(f, f + particles.size(), 0.0);
  }
  for (auto& l : loads) l->apply_to_particles(*this, time);
}

template <int D>
void Simulation<D>::sort() {
  partition.sort(particles, grid, int(materials.size()), shape->rows_below() + shape->rows_above(),
                 threads);
  index_valid_ = false;
  last_sort_ = step;
}

template <int D>
void Simulation<D>::maintain_partition() {
  bool ok = partition.verify(particles, grid, shape->rows_below(), shape->rows_above());
  if (!ok || step - last_sort_ >= sort_every) sort();
}

template <int D>
Energies Simulation<D>::energies() const {
  Energies e;
  e.momentum.assign(D, 0.0);
  const double* m = particles.col(particles.mass);
  for (int d = 0; d < D; ++d) {
    const double* v = particles.col(particles.velocity, d);
    const double* x = particles.col(particles.position, d);
    for (size_t i = 0; i < particles.size(); ++i) {
      e.kinetic += 0.5 * m[i] * v[i] * v[i];
      e.momentum[size_t(d)] += m[i] * v[i];
      e.gravity -= m[i] * gravity[size_t(d)] * x[i];
    }
  }
  for (size_t mat = 0; mat < materials.size(); ++mat) {
    const auto& r = partition.material_ranges[mat];
    if (r.end > r.begin) e.strain += materials[mat]->strain_energy(particles, r.begin, r.end);
  }
  scheme->add_energies(*this, e);
  return e;
}

template <int D>
size_t Simulation<D>::index_of(uint32_t id) const {
  if (!index_valid_) {
    index_of_id_.resize(particles.size());
    for (size_t i = 0; i < particles.size(); ++i) index_of_id_[particles.id[i]] = uint32_t(i);
    index_valid_ = true;
  }
  return index_of_id_[id];
}

template <int D>
bool Simulation<D>::particle_set(const std::string& name, std::vector<uint32_t>& ids) const {
  ids.clear();
  for (const auto& [n, box] : sets_) {
    if (n != name) continue;
    for (size_t i = 0; i < particles.size(); ++i) {
      bool in = true;
      for (int d = 0; d < D; ++d) {
        double x = particles.col(particles.position, d)[i];
        in = in && x >= box.first[size_t(d)] && x <= box.second[size_t(d)];
      }
      if (in) ids.push_back(particles.id[i]);
    }
    return true;
  }
  return false;
}

template <int D>
int Simulation<D>::body_param(const Params& p, const std::string& key, Diagnostics& diag) const {
  if (!p.has(key)) return 0;
  const int b = body_index(p.text(key));
  if (b < 0) {
    std::vector<std::string> names;
    for (const auto& bd : bodies) names.push_back(bd.name);
    diag.error(p.where(key), p.path(key),
               "unknown body '" + p.text(key) + "'; bodies are: " + join(names, ", "));
  }
  return b;
}

template <int D>
int Simulation<D>::body_index(const std::string& name) const {
  for (size_t b = 0; b < bodies.size(); ++b)
    if (bodies[b].name == name) return int(b);
  return -1;
}

template <int D>
bool Simulation<D>::check_particles(std::string& what) const {
  // Parallel scan for the first bad particle; the message is built only on failure.
  const size_t n = particles.size();
  const int nf = 3;
  const int fields[nf] = {particles.position, particles.velocity, particles.stress};
  size_t bad = n;
#pragma omp parallel for reduction(min : bad) schedule(static) num_threads(threads)
  for (size_t i = 0; i < n; ++i) {
    bool ok = true;
    for (int f = 0; f < nf; ++f)
      for (int c = 0; c < particles.info(fields[f]).components; ++c)
        ok = ok && std::isfinite(particles.col(fields[f], c)[i]);
    for (int d = 0; d < D; ++d) {
      const double x = particles.col(particles.position, d)[i];
      ok = ok && x >= grid.origin[size_t(d)] && x <= grid.upper(d);
    }
    if (!ok) bad = std::min(bad, i);
  }
  if (bad == n) return true;
  std::string field;
  for (int f = 0; f < nf && field.empty(); ++f)
    for (int c = 0; c < particles.info(fields[f]).components && field.empty(); ++c)
      if (!std::isfinite(particles.col(fields[f], c)[bad])) {
        const FieldInfo& info = particles.info(fields[f]);
        field = info.name + (info.components > 1 ? "." + info.component_names[size_t(c)] : "") +
                " is not finite";
      }
  for (int d = 0; d < D && field.empty(); ++d) {
    const double x = particles.col(particles.position, d)[bad];
    if (x < grid.origin[size_t(d)] || x > grid.upper(d))
      field = std::string("position.") + "xyz"[d] + " = " + format_number(x) + " (left the grid [" +
              format_number(grid.origin[size_t(d)]) + ", " + format_number(grid.upper(d)) + "])";
  }
  std::ostringstream s;
  s << "particle " << particles.id[bad] << " (body '" << bodies[particles.body[bad]].name
    << "'): " << field;
  what = s.str();
  return false;
}

template class Simulation<1>;
template class Simulation<2>;
template class Simulation<3>;

}  // namespace loam
