// The runtime services of Simulation<D>: the stable time step and one step (advance), sources
// and sinks exchanging particles, the partition and sort, energies, particle field requests, the
// set, body and selection look-ups plugins use, and the stability check of the particles. The model
// is built from the config in simulation_build.cpp.
#include "simulation.hpp"

#include <cmath>
#include <sstream>

namespace loam {

template <int D>
Simulation<D>::~Simulation() = default;

template <int D>
double Simulation<D>::wave_speed() const {
  double c = 0;
  for (const auto& s : sets)
    for (size_t m = 0; m < materials.size(); ++m) c = std::max(c, rank_wave_speed(s, m));
  return c;
}

template <int D>
double Simulation<D>::stable_dt() const {
  if (fixed_dt > 0) return fixed_dt;
  const double c = wave_speed();
  double dt_cfl = cfl * grid.min_cell() / std::max(c + max_speed, 1e-300);
  const double dt_here = std::min(dt_cfl, scheme->stable_dt(*this));
  return ranks->distributed() ? ranks->min(dt_here) : dt_here;
}

template <int D>
bool Simulation<D>::advance(double step_dt, bool check) {
  dt = step_dt;
  prepare_particle_loads();
  shape->begin_step(*this);
  if (ranks->distributed()) failure = ranks->first_message(failure);  // one rank's stops all
  if (!failure.empty()) return false;
  const bool checked = check || (step + 1) % check_every == 0;
  const bool track = checked && track_motion;
  if (track) timed("motion", [&] { keep_positions(); });
  reactions.begin_step();
  if (ledger.enabled) {
    std::vector<size_t> sizes;
    for (const auto& s : sets) sizes.push_back(s.size());
    ledger.begin_step(grid, *ranks, sizes);
  }
  const double load_moment = particle_load_moment();  // sum f . x^n
  scheme->step(*this, dt);
  time += dt;
  ++step;
  const bool distributed = ranks->distributed();
  reactions.end_step(*ranks);
  ledger.end_step(*ranks, particle_load_moment() - load_moment);
  if (distributed) failure = ranks->first_message(failure);  // one rank's failure stops all
  if (!failure.empty()) return false;
  // The largest particle speed over the ranks: the time step's CFL bound is then the serial
  // run's, cfl h / (max c + max |v|), as a MIN over the ranks of cfl h / (c_rank + max |v|);
  // with each rank's own speed it would be cfl h / max (c_rank + v_rank), larger when the
  // fastest wave and the fastest particle are on different ranks.
  if (distributed) max_speed = ranks->max(max_speed);
  if (track)
    timed("motion", [&] {
      motion_speed = largest_move(dt);
      if (distributed) motion_speed = ranks->max(motion_speed);  // a stage's `until: static`
    });
  exchange_particles();
  if (distributed) timed("migration", [&] { migrate_particles(); });
  // Check before sorting: the sort must not see non-finite positions. Under mpirun every rank
  // stops on the first rank's failure, a particle that could not be handed over included.
  bool ok = true;
  if (checked) timed("check_particles", [&] { ok = failure.empty() && check_particles(failure); });
  if (distributed) failure = ranks->first_message(failure), ok = failure.empty();
  if (!ok) return false;
  if (checked) checked_step = step;
  timed("partition", [&] { maintain_partition(); });
  if (checked && keep_last_good) timed("last_good_copy", [&] { save_last_good(); });
  return true;
}

template <int D>
void Simulation<D>::migrate_particles() {
  for (auto& s : sets) {
    long strays = 0, first = -1;
    if (ranks->migrate(s.particles, strays, first)) s.resized = true;
    if (strays > 0 && failure.empty())
      failure = "particle " + std::to_string(first) + " of set '" + s.name +
                "' moved beyond the neighbouring rank's block in one step (" +
                std::to_string(strays) + " such particles on rank " +
                std::to_string(ranks->rank()) +
                "): a particle crossed more than a block; use fewer ranks or a smaller time.cfl";
  }
}

template <int D>
void Simulation<D>::keep_positions() {
  motion_x0_.resize(sets.size());
  for (size_t s = 0; s < sets.size(); ++s) {
    const Particles<D>& P = sets[s].particles;
    const size_t n = P.size();
    std::vector<double>& x0 = motion_x0_[s];
    x0.resize(n * D);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long i = 0; i < long(n); ++i)
      for (int d = 0; d < D; ++d) x0[size_t(i) * D + size_t(d)] = P.col(P.position, d)[i];
  }
}

template <int D>
double Simulation<D>::largest_move(double step_dt) const {
  double m2 = 0;
  for (size_t s = 0; s < sets.size(); ++s) {
    const Particles<D>& P = sets[s].particles;
    const std::vector<double>& x0 = motion_x0_[s];
#pragma omp parallel for reduction(max : m2) schedule(static) num_threads(threads)
    for (long i = 0; i < long(P.size()); ++i) {
      double a = 0;
      for (int d = 0; d < D; ++d) {
        const double dx = P.col(P.position, d)[i] - x0[size_t(i) * D + size_t(d)];
        a += dx * dx;
      }
      m2 = std::max(m2, a);
    }
  }
  return std::sqrt(m2) / step_dt;
}

template <int D>
void Simulation<D>::check_grid(const GridUpdate& u) {
  const long n = long(grid.num_nodes);
  for (int k = 0; k < u.count; ++k) {
    const NodalVector& v = u.phases[size_t(k)].velocity;
    const NodalVector& a = u.phases[size_t(k)].acceleration;
    double sum = 0;
#pragma omp parallel for reduction(+ : sum) schedule(static) num_threads(threads)
    for (long i = 0; i < n; ++i)
      for (int d = 0; d < D; ++d) sum += 0.0 * v.at(size_t(i), d) + 0.0 * a.at(size_t(i), d);
    if (sum == 0.0) continue;
    for (size_t i = 0; i < grid.num_nodes; ++i)
      for (int d = 0; d < D; ++d)
        for (const auto& [what, value] :
             {std::pair<const char*, double>{"velocity", v.at(i, d)}, {"acceleration", a.at(i, d)}})
          if (!std::isfinite(value)) {
            std::string at;
            for (int c = 0; c < D; ++c)
              at += (c ? ", " : "") + format_number(grid.node_coord(i, c));
            failure = "grid node " + std::to_string(i) + " at (" + at + ")" +
                      (u.count > 1 ? (k == 0 ? " (solid)" : " (water)") : "") + ": " + what + "." +
                      std::string(1, char('x' + d)) + " = " + format_number(value) +
                      " after the grid update";
            return;
          }
  }
}

template <int D>
void Simulation<D>::save_last_good() {
  last_good.time = time;
  last_good.dt = dt;
  last_good.max_speed = max_speed;
  last_good.step = step;
  last_good.sets.resize(sets.size());
  last_good.layouts.resize(sets.size());
  for (size_t k = 0; k < sets.size(); ++k) {
    const ParticleSet<D>& s = sets[k];
    s.particles.copy_to(last_good.sets[k], threads);
    auto& l = last_good.layouts[k];
    l.slabs = s.partition.slabs;
    l.material_ranges = s.partition.material_ranges;
    l.threads = s.partition.threads;
    l.last_sort = s.last_sort;
    l.resized = s.resized;
  }
}

template <int D>
void Simulation<D>::swap_last_good() {
  std::swap(time, last_good.time);
  std::swap(dt, last_good.dt);
  std::swap(max_speed, last_good.max_speed);
  std::swap(step, last_good.step);
  for (size_t k = 0; k < sets.size(); ++k) {
    ParticleSet<D>& s = sets[k];
    auto& l = last_good.layouts[k];
    std::swap(s.particles, last_good.sets[k]);
    std::swap(s.partition.slabs, l.slabs);
    std::swap(s.partition.material_ranges, l.material_ranges);
    std::swap(s.partition.threads, l.threads);
    std::swap(s.last_sort, l.last_sort);
    std::swap(s.resized, l.resized);
  }
}

template <int D>
void Simulation<D>::add_particles(int b, const std::vector<Vec>& x, const Vec& v) {
  if (x.empty()) return;
  const Body& body = bodies[size_t(b)];
  ParticleSet<D>& set = sets[size_t(body.set)];
  Particles<D>& P = set.particles;
  std::vector<size_t> kept;  // the points of x this rank keeps: all serially
  kept.reserve(x.size());
  const auto block = ranks->cell_block(grid);
  for (size_t k = 0; k < x.size(); ++k) {
    bool own = true;
    for (int d = 0; d < D && own; ++d) {
      const int c = grid.cell_of(x[k][size_t(d)], d);
      own = c >= block.lo[size_t(d)] && c < block.hi[size_t(d)];
    }
    if (own) kept.push_back(k);
  }
  const uint32_t first = next_id_;
  next_id_ += uint32_t(x.size());
  if (kept.empty()) return;
  const size_t begin = P.size(), end = begin + kept.size();
  P.resize(end);
  double vol = 1;
  for (int d = 0; d < D; ++d) vol *= body.spacing[size_t(d)];
  for (size_t i = begin; i < end; ++i) {
    const size_t k = kept[i - begin];
    P.id[i] = first + uint32_t(k);
    P.material[i] = uint16_t(b);
    P.body[i] = uint16_t(b);
    for (int d = 0; d < D; ++d) {
      P.col(P.position, d)[i] = x[k][size_t(d)];
      P.col(P.velocity, d)[i] = v[size_t(d)];
    }
    P.col(P.volume)[i] = vol;
    P.col(P.mass)[i] = vol * materials[size_t(b)]->density();
  }
  // The same initialisation as at set-up, on the new range only.
  shape->initialize_particles(*this, set, begin, end);
  scheme->initialize_particles(*this, set, begin, end);
  materials[size_t(b)]->initialize(P, begin, end);
  restart_displacement(P, begin, end);
  for (size_t i = begin; i < end; ++i) mass_created += P.col(P.mass)[i];
  carry_energy(P, begin, end, 1.0);
  created += kept.size();
  set.invalidate_index();
  set.resized = true;
}

template <int D>
void Simulation<D>::exchange_particles() {
  apply_sinks();
  for (auto& p : sources) p->apply(*this, time);
}

template <int D>
void Simulation<D>::apply_sinks() {
  if (sinks.empty()) return;
  std::vector<uint8_t> remove;
  for (auto& set : sets) {
    remove.assign(set.size(), 0);
    for (const auto& k : sinks) k->mark(*this, set, remove);
    size_t n = 0;
    const double* m = set.particles.col(set.particles.mass);
    for (size_t i = 0; i < set.size(); ++i)
      if (remove[i]) mass_removed += m[i], ++n;
    if (n == 0) continue;
    carry_energy(set.particles, 0, set.size(), -1.0, remove.data());
    set.particles.erase(remove);
    set.invalidate_index();
    set.resized = true;
    removed += n;
  }
}

template <int D>
double Simulation<D>::total_mass() const {
  double m = 0;
  for (const auto& set : sets) m += set.mass();
  return m;
}

template <int D>
double Simulation<D>::particle_load_moment() const {
  if (external_force < 0 || !ledger.enabled) return 0.0;
  double sum = 0;
  for (const auto& s : sets)
    for (int d = 0; d < D; ++d) {
      const double* f = s.particles.col(external_force, d);
      const double* x = s.particles.col(s.particles.position, d);
      for (size_t i = 0; i < s.size(); ++i) sum += f[i] * x[i];
    }
  return sum;
}

template <int D>
void Simulation<D>::carry_energy(const Particles<D>& P, size_t begin, size_t end, double sign,
                                 const uint8_t* only) {
  if (!ledger.enabled) return;
  auto& t = ledger.totals;
  const double* m = P.col(P.mass);
  for (size_t i = begin; i < end; ++i) {
    if (only && !only[i]) continue;
    for (int d = 0; d < D; ++d) {
      const double v = P.col(P.velocity, d)[i];
      t.carried_kinetic += sign * 0.5 * m[i] * v * v;
      t.carried_gravity -= sign * m[i] * gravity[size_t(d)] * P.col(P.position, d)[i];
    }
    const double w = materials[P.material[i]]->strain_energy(P, i, i + 1);
    if (!std::isnan(w)) t.carried_stored += sign * w;
  }
}

template <int D>
void Simulation<D>::prepare_particle_loads() {
  if (external_force < 0) return;
  for (auto& s : sets)
    for (int d = 0; d < D; ++d) {
      double* f = s.particles.col(external_force, d);
      std::fill(f, f + s.size(), 0.0);
    }
  for (auto& l : loads) l->apply_to_particles(*this, time - loads_start);
}

template <int D>
void Simulation<D>::sort(ParticleSet<D>& s) {
  s.partition.sort(s.particles, grid, int(materials.size()),
                   shape->rows_below() + shape->rows_above(), threads);
  s.invalidate_index();
  s.resized = false;
  s.last_sort = step;
}

template <int D>
void Simulation<D>::sort() {
  for (auto& s : sets) sort(s);
}

template <int D>
void Simulation<D>::maintain_partition() {
  for (auto& s : sets) {
    // A changed count (sources, sinks) needs new slabs; otherwise sort when drift requires it.
    bool ok = !s.resized &&
              s.partition.verify(s.particles, grid, shape->rows_below(), shape->rows_above());
    if (!ok || step - s.last_sort >= sort_every) sort(s);
  }
}

template <int D>
Energies Simulation<D>::energies() const {
  Energies e;
  e.momentum.assign(D, 0.0);
  for (const auto& s : sets) {
    const Particles<D>& P = s.particles;
    const double* m = P.col(P.mass);
    for (int d = 0; d < D; ++d) {
      const double* v = P.col(P.velocity, d);
      const double* x = P.col(P.position, d);
      for (size_t i = 0; i < P.size(); ++i) {
        e.kinetic += 0.5 * m[i] * v[i] * v[i];
        e.momentum[size_t(d)] += m[i] * v[i];
        e.gravity -= m[i] * gravity[size_t(d)] * x[i];
      }
    }
    for (size_t mat = 0; mat < materials.size(); ++mat) {
      const auto& r = s.partition.material_ranges[mat];
      if (r.end > r.begin) e.strain += materials[mat]->strain_energy(P, r.begin, r.end);
    }
  }
  scheme->add_energies(*this, e);
  if (ranks->distributed()) {  // the whole model's, on every rank
    std::vector<double> v{e.kinetic, e.strain, e.gravity};
    v.insert(v.end(), e.momentum.begin(), e.momentum.end());
    ranks->sum(v.data(), int(v.size()));
    e.kinetic = v[0], e.strain = v[1], e.gravity = v[2];
    std::copy(v.begin() + 3, v.end(), e.momentum.begin());
  }
  return e;
}

template <int D>
int Simulation<D>::request_field(const FieldInfo& info, int only) {
  int h = -1;
  for (size_t s = 0; s < sets.size(); ++s) {
    const int hs = sets[s].particles.request(info, only < 0 || int(s) == only);
    if (h >= 0 && hs != h)
      throw std::logic_error("field '" + info.name +
                             "': sets have different layouts (request fields through "
                             "Simulation::request_field)");
    h = hs;
  }
  return h;
}

template <int D>
int Simulation<D>::request_deformation_gradient() {
  for (auto& s : sets) deformation_gradient = s.particles.request_deformation_gradient();
  return deformation_gradient;
}

template <int D>
size_t Simulation<D>::num_particles() const {
  size_t n = 0;
  for (const auto& s : sets) n += s.size();
  return n;
}

template <int D>
int Simulation<D>::set_index(const std::string& name) const {
  for (size_t s = 0; s < sets.size(); ++s)
    if (sets[s].name == name) return int(s);
  return -1;
}

template <int D>
int Simulation<D>::set_param(const Params& p, const std::string& key, Diagnostics& diag) const {
  if (!p.has(key)) return 0;
  const int s = set_index(p.text(key));
  if (s < 0) {
    std::vector<std::string> names;
    for (const auto& decl : scheme->particle_sets())
      names.push_back(decl.name + " (" + decl.meaning + ")");
    diag.error(p.where(key), p.path(key),
               "unknown particle set '" + p.text(key) + "'; scheme '" +
                   config.section("scheme").type() + "' has: " + join(names, ", "));
  }
  return s;
}

template <int D>
bool Simulation<D>::selection(const std::string& name, const ParticleSet<D>& set,
                              std::vector<uint32_t>& ids) const {
  ids.clear();
  const Particles<D>& P = set.particles;
  for (const auto& [n, box] : selections_) {
    if (n != name) continue;
    for (size_t i = 0; i < P.size(); ++i) {
      bool in = true;
      for (int d = 0; d < D; ++d) {
        double x = P.col(P.position, d)[i];
        in = in && x >= box.first[size_t(d)] && x <= box.second[size_t(d)];
      }
      if (in) ids.push_back(P.id[i]);
    }
    return true;
  }
  return false;
}

template <int D>
int Simulation<D>::body_param(const Params& p, const std::string& key, Diagnostics& diag,
                              bool need_particles) const {
  if (!p.has(key)) {  // the first body with particles at t = 0
    for (size_t b = 0; b < bodies.size(); ++b)
      if (bodies[b].count > 0) return int(b);
    return 0;
  }
  const int b = body_index(p.text(key));
  if (b < 0) {
    unknown_body(diag, p.where(key), p.path(key), p.text(key));
  } else if (need_particles && bodies[size_t(b)].count == 0) {
    diag.error(p.where(key), p.path(key),
               "body '" + p.text(key) + "' has no particles at t = 0 (no generator)");
    return -1;
  }
  return b;
}

template <int D>
int Simulation<D>::body_index(const std::string& name) const {
  const auto& bl = config.list("bodies");
  for (size_t b = 0; b < bl.size(); ++b)
    if (bl[b].text("name") == name) return int(b);
  return -1;
}

template <int D>
void Simulation<D>::unknown_body(Diagnostics& diag, const Location& where, const std::string& path,
                                 const std::string& name) const {
  std::vector<std::string> names;
  for (const auto& b : config.list("bodies")) names.push_back(b.text("name"));
  diag.error(where, path, "unknown body '" + name + "'; bodies are: " + join(names, ", "));
}

template <int D>
void Simulation<D>::restart_displacement(Particles<D>& P, size_t begin, size_t end) const {
  const int x0 = P.find("initial_position");  // the output's displacement reference
  if (!P.has(x0)) return;
  copy_columns(P, P.position, x0, D, begin, end);
  const int F0 = P.find("reset_deformation_gradient");  // the strain output's reference
  if (P.has(F0)) copy_columns(P, deformation_gradient, F0, D * D, begin, end);
}

template <int D>
void Simulation<D>::copy_columns(Particles<D>& P, int from, int to, int components, size_t begin,
                                 size_t end) {
  for (int c = 0; c < components; ++c)
    std::copy(P.col(from, c) + begin, P.col(from, c) + end, P.col(to, c) + begin);
}

template <int D>
int Simulation<D>::request_strain_reference() {
  request_displacement_reference();  // a reset resets both
  request_deformation_gradient();
  FieldInfo info = Particles<D>::deformation_gradient_info();
  info.name = "reset_deformation_gradient";
  info.doc = "deformation gradient at the last displacement reset (the identity at t = 0)";
  const Particles<D>& p0 = sets[0].particles;
  const bool is_new = !p0.has(p0.find(info.name));
  const int h = request_field(info);
  if (is_new)
    for (auto& s : sets) copy_columns(s.particles, deformation_gradient, h, D * D, 0, s.size());
  return h;
}

template <int D>
int Simulation<D>::request_displacement_reference() {
  const Particles<D>& p0 = sets[0].particles;
  const bool is_new = !p0.has(p0.find("initial_position"));
  const int h = request_field({"initial_position", D, "m",
                               "position at the last displacement reset (t = 0, or a stage's "
                               "reset: [displacement])",
                               Particles<D>::axis_names()});
  if (is_new)
    for (auto& s : sets) restart_displacement(s.particles, 0, s.particles.size());
  return h;
}

template <int D>
bool Simulation<D>::check_particles(std::string& what) const {
  for (const auto& s : sets)
    if (!check_particles(s, what)) return false;
  return true;
}

template <int D>
bool Simulation<D>::check_particles(const ParticleSet<D>& set, std::string& what) const {
  // Parallel scan for the first bad particle; the message is built only on failure.
  const Particles<D>& particles = set.particles;
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
  s << "particle " << particles.id[bad] << " (body '" << bodies[particles.body[bad]].name << "'"
    << (sets.size() > 1 ? ", set '" + set.name + "'" : "") << "): " << field;
  what = s.str();
  return false;
}

template class Simulation<1>;
template class Simulation<2>;
template class Simulation<3>;

}  // namespace loam
