// The output of a run: the output fields and probes checked against the model, the output
// directory, frames (through the writer plugin, derived fields such as displacement refreshed),
// the probe CSVs and history.csv. The loop that calls these is in runner.cpp.
#include "run.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>

#include "registry.hpp"
#include "strain_measure.hpp"

namespace loam {
namespace detail {

namespace {

/// Output fields that are not stored but derived when written: the displacement and the
/// magnitude of the logarithmic strain, both since the last displacement reset.
bool derived_field(const std::string& name) {
  return name == "displacement" || name == "strain_magnitude";
}

}  // namespace

/// The grid indices of the node nearest to a probe's node_near point; a point outside the grid
/// is a located error (then the nearest node inside).
template <int D>
std::vector<double> Run<D>::nearest_node(const Params& pr, Diagnostics& diag) const {
  const Grid<D>& g = sim_->grid;
  const auto& x = pr.vec("node_near");
  std::vector<double> ijk(static_cast<size_t>(D), 0.0);
  bool inside = true;
  for (int d = 0; d < D; ++d) {
    const double t = (x[size_t(d)] - g.origin[size_t(d)]) / g.cell[size_t(d)];
    inside = inside && t > -1e-9 && t < g.cells[d] + 1e-9;
    ijk[size_t(d)] = double(std::clamp(std::lround(t), 0L, long(g.nodes[d] - 1)));
  }
  if (!inside)
    diag.error(pr.where("node_near"), pr.path("node_near"), "the point is outside the grid");
  return ijk;
}

template <int D>
void Run<D>::locate_probe_node(const Params& pr, Probe<D>& probe, Diagnostics& diag) const {
  std::array<int, D> node{};
  const auto ijk = pr.has("node") ? pr.vec("node") : nearest_node(pr, diag);
  for (int d = 0; d < D; ++d) {
    long k = std::lround(ijk[size_t(d)]);
    if (k < 0 || k >= sim_->grid.nodes[d] || std::fabs(ijk[size_t(d)] - double(k)) > 1e-9) {
      diag.error(pr.where("node"), pr.path("node"),
                 "node index " + format_number(ijk[size_t(d)]) + " along " + "xyz"[d] +
                     " is not an integer in [0, " + std::to_string(sim_->grid.nodes[d] - 1) + "]");
    }
    node[size_t(d)] = int(std::max(0L, k));
  }
  // Under mpirun the rank that owns the node samples it (every copy of a node holds the
  // whole grid's value, the owner's is the one its boundary conditions act on).
  probe.samples_node = sim_->ranks->owns_node(sim_->grid, node);
  if (probe.samples_node) probe.node = sim_->grid.node_index(node);
}

template <int D>
bool Run<D>::locate_probe_particle(const Params& pr, Probe<D>& probe, Diagnostics& diag) {
  probe.set = sim_->set_param(pr, "set", diag);
  if (probe.set < 0) return false;
  const Particles<D>& ps = sim_->sets[size_t(probe.set)].particles;
  for (const auto& name : probe.fields)
    if (!derived_field(name) && !ps.has(ps.find(name)))
      diag.error(pr.where("fields"), pr.path("fields"),
                 "particle set '" + sim_->sets[size_t(probe.set)].name +
                     "' does not store field '" + name + "'");
  // The nearest particle of the set, those of its bodies that wait for a stage included
  // (until its body joins the run, the probe's rows hold nan).
  const auto& target = pr.vec("particle_near");
  double best = 1e300;
  auto nearest = [&](const Particles<D>& candidates) {
    for (size_t i = 0; i < candidates.size(); ++i) {
      double r2 = 0;
      for (int d = 0; d < D; ++d) {
        double dx = candidates.col(candidates.position, d)[i] - target[size_t(d)];
        r2 += dx * dx;
      }
      if (r2 < best) best = r2, probe.particle_id = candidates.id[i];
    }
  };
  nearest(ps);
  for (size_t b = 0; b < sim_->bodies.size(); ++b)
    if (sim_->body_set(int(b)) == probe.set) nearest(sim_->waiting_particles(int(b)));
  // Under mpirun, the nearest over the ranks; of equally near ones the lowest id, as the
  // serial search (its candidates are in id order) finds.
  const auto all = sim_->ranks->all_gather({best, double(probe.particle_id)});
  for (size_t r = 0; r < all.size(); r += 2)
    if (all[r] < best || (all[r] == best && all[r + 1] < double(probe.particle_id)))
      best = all[r], probe.particle_id = uint32_t(all[r + 1]);
  if (best == 1e300) {
    diag.error(pr.where("set"), pr.path("set"), "the particle set has no particles");
    return false;
  }
  return true;
}

template <int D>
void Run<D>::check_outputs(Diagnostics& diag) {
  // strain_magnitude needs F and its value at the last reset: requested before the names are
  // checked, so that deformation_gradient can be written beside it.
  auto names_strain = [](const std::vector<std::string>& f) {
    return std::find(f.begin(), f.end(), "strain_magnitude") != f.end();
  };
  bool need_strain = names_strain(cfg_.params.section("output").strings("fields"));
  for (const auto& pr : cfg_.params.list("probes"))
    need_strain = need_strain || (!pr.has("particle_near") && names_strain(pr.strings("fields")));
  if (need_strain) {
    reset_F_ = sim_->request_strain_reference();
    strain_magnitude_ = sim_->request_field(
        {"strain_magnitude",
         1,
         "-",
         "sqrt(eps:eps) of the logarithmic strain since the last displacement reset",
         {}});
  }
  // Every set has the same field layout; a name is known if some set stores it.
  const Particles<D>& p = sim_->sets[0].particles;
  std::vector<std::string> known;
  for (int f = 0; f < p.num_fields(); ++f) {
    bool stored = false;
    for (const auto& s : sim_->sets) stored = stored || s.particles.has(f);
    if (stored) known.push_back(p.info(f).name);
  }
  known.push_back("displacement");
  if (!need_strain) known.push_back("strain_magnitude");
  auto check_name = [&](const Params& sec, size_t i, const std::string& name, bool node) {
    std::vector<std::string> options = known;
    if (node) {
      options.clear();
      for (const auto& g : sim_->scheme->grid_fields()) options.push_back(g.name);
    }
    if (std::find(options.begin(), options.end(), name) != options.end()) return true;
    std::string path = sec.path("fields") + "." + std::to_string(i);
    diag.error(sec.where("fields", i), path,
               "unknown " + std::string(node ? "node" : "particle") + " field '" + name + "'" +
                   suggest(name, options, "available fields"));
    return false;
  };
  const Params& out = cfg_.params.section("output");
  const auto& names = out.strings("fields");
  bool need_disp = false;
  for (size_t i = 0; i < names.size(); ++i)
    if (check_name(out, i, names[i], false)) {
      if (names[i] == "displacement")
        need_disp = true;
      else if (derived_field(names[i]))
        continue;  // strain_magnitude: added in the order given below
      else if (names[i] != "position")
        frame_fields_.push_back(p.find(names[i]));  // one layout: valid in every set
    }
  // A staged run reports each stage's largest displacement (since the last reset).
  if (!cfg_.params.list("stages").empty()) need_disp = true;
  for (const auto& pr : cfg_.params.list("probes")) {
    Probe<D> probe;
    probe.name = pr.text("name");
    probe.every = pr.integer("every_steps");
    probe.on_node = pr.has("node") || pr.has("node_near");
    if (int(pr.has("node")) + int(pr.has("node_near")) + int(pr.has("particle_near")) != 1) {
      diag.error(pr.where(), pr.path(),
                 "give exactly one of 'particle_near', 'node' or 'node_near'");
      continue;
    }
    const auto& f = pr.strings("fields");
    for (size_t i = 0; i < f.size(); ++i)
      if (check_name(pr, i, f[i], probe.on_node)) {
        probe.fields.push_back(f[i]);
        need_disp = need_disp || f[i] == "displacement";
      }
    if (probe.on_node)
      locate_probe_node(pr, probe, diag);
    else if (!locate_probe_particle(pr, probe, diag))
      continue;
    probes_.push_back(std::move(probe));
  }
  for (size_t i = 0; i < probes_.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      if (probes_[i].name == probes_[j].name)
        diag.error(cfg_.params.where("probes"), "probes." + std::to_string(i) + ".name",
                   "duplicate probe name '" + probes_[i].name + "'");
  if (need_disp) {
    initial_position_ = sim_->request_displacement_reference();
    displacement_ = sim_->request_field(
        {"displacement", D, "m", "position minus initial position", Particles<D>::axis_names()});
  }
  for (const auto& n : names) {  // in the order given
    if (n == "displacement") frame_fields_.push_back(displacement_);
    if (n == "strain_magnitude") frame_fields_.push_back(strain_magnitude_);
  }
}

template <int D>
fs::path Run<D>::output_directory() const {
  return opt_.out_dir.empty() ? fs::path("results") / cfg_.name : fs::path(opt_.out_dir);
}

template <int D>
std::string Run<D>::prepare_directory() {
  dir_ = output_directory();
  std::error_code ec;
  if (fs::exists(dir_) && !fs::is_directory(dir_))
    return "output path " + dir_.string() + " is a file";
  if (fs::exists(dir_) && !fs::is_empty(dir_)) {
    if (!opt_.overwrite)
      return "output directory " + dir_.string() +
             " is not empty; pass --overwrite to replace its results or --out DIR";
    // Remove only what loam writes, never foreign files.
    for (const auto& e : fs::directory_iterator(dir_)) {
      std::string n = e.path().filename().string(), ext = e.path().extension().string();
      if (ext == ".h5" || ext == ".xdmf" || ext == ".csv" || ext == ".tmp" || n == "summary.json")
        fs::remove(e.path(), ec);
    }
  }
  fs::create_directories(dir_, ec);
  if (ec) return "cannot create output directory " + dir_.string() + ": " + ec.message();
  return "";
}

template <int D>
double Run<D>::strain_magnitude(const Particles<D>& p, size_t i) const {
  double F[D * D], F0[D * D];
  for (int c = 0; c < D * D; ++c)
    F[c] = p.col(sim_->deformation_gradient, c)[i], F0[c] = p.col(reset_F_, c)[i];
  return hencky_strain_norm<D>(F, F0);
}

template <int D>
void Run<D>::refresh_derived() {
  if (strain_magnitude_ >= 0)
    for (auto& s : sim_->sets) {
      Particles<D>& p = s.particles;
      double* out = p.col(strain_magnitude_);
      for (size_t i = 0; i < p.size(); ++i) out[i] = strain_magnitude(p, i);
    }
  if (displacement_ < 0) return;
  for (auto& s : sim_->sets) {
    Particles<D>& p = s.particles;
    for (int d = 0; d < D; ++d) {
      const double* x = p.col(p.position, d);
      const double* x0 = p.col(initial_position_, d);
      double* u = p.col(displacement_, d);
      for (size_t i = 0; i < p.size(); ++i) u[i] = x[i] - x0[i];
    }
  }
}

template <int D>
void Run<D>::open_outputs(long resume_step) {
  writer_ = Registry::instance().create<Writer, D>(cfg_.params.section("output").section("writer"));
  writer_->open(dir_.string(), *sim_, frame_fields_);
  if (!sim_->ranks->root()) return;  // history and probes are the first rank's
  const int history_digits = int(cfg_.params.section("output").integer("history_digits"));
  if (resume_step >= 0) {  // the files go on from the checkpoint's step
    history_.open_resume(dir_ / "history.csv", resume_step, history_digits);
    for (auto& pr : probes_) pr.csv.open_resume(dir_ / ("probe_" + pr.name + ".csv"), resume_step);
    return;
  }
  history_.open(dir_ / "history.csv", history_digits);
  history_.out() << "step,time,dt,kinetic_energy,strain_energy,gravity_energy,total_energy";
  for (int d = 0; d < D; ++d)
    history_.out() << ",momentum_"
                   << "xyz"[d];
  if (exchanges_particles()) history_.out() << ",particles,mass_created,mass_removed";
  if (sim_->ledger.enabled)
    history_.out() << ",dissipation_material,dissipation_damping,dissipation_transfer,dissipation_"
                      "drag,work_loads,"
                      "work_boundaries,energy_carried,energy_balance";
  if (sim_->ledger.enabled && sim_->contact) history_.out() << ",dissipation_contact";
  for (const auto& name : sim_->reactions.names())
    for (int k = 0; k < sim_->scheme->phases(); ++k)
      for (int d = 0; d < D; ++d)
        history_.out() << ",reaction_" << name << (k ? "_water_" : "_") << "xyz"[d];
  for (const auto& name : sim_->rigid_records.names()) {
    const int R = RigidRecords<D>::R;
    for (int d = 0; d < D; ++d)
      history_.out() << ",rigid_" << name << "_displacement_"
                     << "xyz"[d];
    for (const char* what : {"_rotation", "_moment"})
      for (int k = 0; k < R; ++k)
        history_.out() << ",rigid_" << name << what << (R > 1 ? std::string("_") + "xyz"[k] : "");
  }
  history_.out() << "\n";
  for (auto& pr : probes_) {
    pr.csv.open(dir_ / ("probe_" + pr.name + ".csv"));
    pr.csv.out() << "step,time";
    for (const auto& f : pr.fields) {
      int nc = 1;
      std::vector<std::string> names;
      if (pr.on_node) {
        for (const auto& g : sim_->scheme->grid_fields())
          if (g.name == f) nc = g.components;
        for (int c = 0; c < nc; ++c) names.push_back(nc > 1 ? std::string(1, "xyz"[c]) : "");
      } else {
        const Particles<D>& p = sim_->sets[size_t(pr.set)].particles;
        int h = f == "displacement" ? displacement_ : p.find(f);
        nc = p.info(h).components;
        names = p.info(h).component_names;
      }
      for (int c = 0; c < nc; ++c)
        pr.csv.out() << "," << f << (nc > 1 ? "_" + names[size_t(c)] : "");
    }
    pr.csv.out() << "\n";
  }
}

/// The probes due at this step (all with `force`): each probe's values are taken where its
/// particle or node is (under mpirun on one rank), gathered on the first rank (one message per
/// rank for all probes) and written there as one row per probe.
template <int D>
void Run<D>::sample_probes(bool force) {
  std::vector<size_t> due, widths;
  std::vector<double> mine;  // per due probe: 1 if sampled here (else 0), then its values
  for (size_t k = 0; k < probes_.size(); ++k)
    if (force || sim_->step % probes_[k].every == 0) {
      due.push_back(k);
      const size_t at = mine.size();
      mine.push_back(0.0);
      const bool here = take_probe_sample(probes_[k], mine);
      mine[at] = here ? 1.0 : 0.0;
      widths.push_back(mine.size() - at - 1);
    }
  if (due.empty()) return;
  const std::vector<double> all = sim_->ranks->gather(mine);
  if (!sim_->ranks->root()) return;
  for (size_t j = 0, at = 0; j < due.size(); at += 1 + widths[j], ++j) {
    Probe<D>& pr = probes_[due[j]];
    auto& o = pr.csv.out();
    o << sim_->step << "," << sim_->time;
    size_t from = all.size();  // the first rank that sampled it
    for (size_t r = 0; r < all.size(); r += mine.size())
      if (all[r + at] != 0) {
        from = r + at + 1;
        break;
      }
    for (size_t c = 0; c < widths[j]; ++c) {
      // Not in the run: its body waits for a stage, or a sink took it.
      if (from == all.size())
        o << ",nan";
      else
        o << "," << all[from + c];
    }
    o << "\n";
    pr.csv.check();
  }
}

/// Appends probe pr's values at this step to `values` (nan where this rank does not hold its
/// particle or node); returns whether it holds it.
template <int D>
bool Run<D>::take_probe_sample(const Probe<D>& pr, std::vector<double>& values) const {
  const double nan = std::nan("");
  if (pr.on_node) {
    for (const auto& f : pr.fields)
      for (const auto& g : sim_->scheme->grid_fields())
        if (g.name == f)
          for (int c = 0; c < g.components; ++c)
            values.push_back(
                pr.samples_node ? g.base[pr.node * size_t(g.stride) + size_t(g.offset + c)] : nan);
    return pr.samples_node;
  }
  const ParticleSet<D>& set = sim_->sets[size_t(pr.set)];
  const Particles<D>& p = set.particles;
  const size_t i = set.index_of(pr.particle_id);
  const bool here = i != set.npos;
  for (const auto& f : pr.fields) {
    if (f == "displacement") {
      for (int d = 0; d < D; ++d)
        values.push_back(here ? p.col(p.position, d)[i] - p.col(initial_position_, d)[i] : nan);
    } else if (f == "strain_magnitude") {
      values.push_back(here ? strain_magnitude(p, i) : nan);
    } else {
      const int h = p.find(f);
      for (int c = 0; c < p.info(h).components; ++c) values.push_back(here ? p.col(h, c)[i] : nan);
    }
  }
  return here;
}

template <int D>
void Run<D>::write_history() {
  Energies e = sim_->energies();  // over all ranks: every rank calls this
  // Particles and the mass created and removed so far, over the ranks.
  double exchanged[3] = {double(sim_->num_particles()), sim_->mass_created, sim_->mass_removed};
  if (exchanges_particles()) sim_->ranks->sum(exchanged, 3);
  EnergyBalance b;
  if (sim_->ledger.enabled) b = energy_balance(e, ls_.e0, sim_->ledger.global(*sim_->ranks));
  if (!sim_->ranks->root()) return;
  auto& o = history_.out();
  double strain = std::isnan(e.strain) ? 0.0 : e.strain;
  o << sim_->step << "," << sim_->time << "," << sim_->dt << "," << e.kinetic << "," << e.strain
    << "," << e.gravity << "," << e.kinetic + strain + e.gravity;
  for (double m : e.momentum) o << "," << m;
  if (exchanges_particles())
    o << "," << size_t(exchanged[0]) << "," << exchanged[1] << "," << exchanged[2];
  if (sim_->ledger.enabled)
    for (double x :
         {b.material, b.damping, b.transfer, b.drag, b.loads, b.boundaries, b.carried, b.balance})
      o << "," << x;
  if (sim_->ledger.enabled && sim_->contact) o << "," << b.contact;
  const Reactions<D>& r = sim_->reactions;
  for (size_t c = 0; c < r.names().size(); ++c)
    for (int k = 0; k < sim_->scheme->phases(); ++k)
      for (int d = 0; d < D; ++d) o << "," << r.force(c)[k * D + d];
  const RigidRecords<D>& rigid = sim_->rigid_records;
  for (size_t c = 0; c < rigid.names().size(); ++c)
    for (int k = 0; k < D + 2 * RigidRecords<D>::R; ++k) o << "," << rigid.values(c)[k];
  o << "\n";
  history_.check();
}

template <int D>
void Run<D>::write_summary(const nlohmann::json& summary) {
  write_file_atomically((dir_ / "summary.json").string(), summary.dump(2) + "\n");
}

template <int D>
void Run<D>::write_frame(const std::string& label) {
  refresh_derived();
  writer_->write(*sim_, label);
  ++frames_;
}

// The class is instantiated once, here (`template class`); runner.cpp and run_checkpoint.cpp
// instantiate the members they define where they use them or explicitly.
template class Run<1>;
template class Run<2>;
template class Run<3>;

}  // namespace detail
}  // namespace loam
