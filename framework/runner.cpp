#include "runner.hpp"

#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "registry.hpp"
#include "simulation.hpp"
#include "writer.hpp"

namespace fs = std::filesystem;

namespace loam {

namespace {

using Clock = std::chrono::steady_clock;

/// A CSV written under a temporary name and renamed when complete.
class CsvFile {
 public:
  void open(const fs::path& path) {
    final_ = path;
    tmp_ = path;
    tmp_ += ".tmp";
    out_.open(tmp_);
    out_.precision(12);
  }
  std::ofstream& out() { return out_; }
  void close() {
    if (!out_.is_open()) return;
    out_.close();
    fs::rename(tmp_, final_);
  }

 private:
  fs::path final_, tmp_;
  std::ofstream out_;
};

template <int D>
struct Probe {
  std::string name;
  bool on_node = false;
  int set = 0;
  uint32_t particle_id = 0;
  size_t node = 0;
  std::vector<std::string> fields;
  long every = 1;
  CsvFile csv;
};

/// Output fields that are not stored but derived when written.
bool derived_field(const std::string& name) {
  return name == "displacement";
}

template <int D>
class Run {
 public:
  Run(const LoadedConfig& cfg, const RunOptions& opt) : cfg_(cfg), opt_(opt) {}

  RunResult execute(bool check_only) {
    RunResult res;
    Diagnostics diag;
    int threads = opt_.threads > 0 ? opt_.threads : omp_get_max_threads();
    sim_ = std::make_unique<Simulation<D>>(cfg_.params, threads, diag);
    if (sim_->model_checked) check_outputs(diag);
    if (sim_) sim_->profiling = opt_.profile;
    if (!diag.ok()) {
      res.exit_code = 2;
      res.message = diag.format();
      return res;
    }
    if (check_only) {
      res.summary = base_summary();
      return res;
    }
    if (opt_.write_output) {
      std::string err = prepare_directory();
      if (!err.empty()) {
        res.exit_code = 2;
        res.message = "loam: error: " + err + "\n";
        return res;
      }
    }
    return loop();
  }

 private:
  const LoadedConfig& cfg_;
  const RunOptions& opt_;
  std::unique_ptr<Simulation<D>> sim_;
  std::unique_ptr<Writer<D>> writer_;
  std::vector<int> frame_fields_;
  std::vector<Probe<D>> probes_;
  CsvFile history_;
  fs::path dir_;
  int displacement_ = -1, initial_position_ = -1;
  long frames_ = 0;

  void check_outputs(Diagnostics& diag) {
    // Every set has the same field layout; a name is known if some set stores it.
    const Particles<D>& p = sim_->sets[0].particles;
    std::vector<std::string> known;
    for (int f = 0; f < p.num_fields(); ++f) {
      bool stored = false;
      for (const auto& s : sim_->sets) stored = stored || s.particles.has(f);
      if (stored) known.push_back(p.info(f).name);
    }
    known.push_back("displacement");
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
        if (derived_field(names[i]))
          need_disp = true;
        else if (names[i] != "position")
          frame_fields_.push_back(p.find(names[i]));  // one layout: valid in every set
      }
    for (const auto& pr : cfg_.params.list("probes")) {
      Probe<D> probe;
      probe.name = pr.text("name");
      probe.every = pr.integer("every_steps");
      probe.on_node = pr.has("node");
      if (pr.has("node") == pr.has("particle_near")) {
        diag.error(pr.where(), pr.path(), "give exactly one of 'particle_near' or 'node'");
        continue;
      }
      const auto& f = pr.strings("fields");
      for (size_t i = 0; i < f.size(); ++i)
        if (check_name(pr, i, f[i], probe.on_node)) {
          probe.fields.push_back(f[i]);
          if (derived_field(f[i])) need_disp = true;
        }
      if (probe.on_node) {
        size_t idx = 0;
        const auto& ijk = pr.vec("node");
        for (int d = 0; d < D; ++d) {
          long k = std::lround(ijk[size_t(d)]);
          if (k < 0 || k >= sim_->grid.nodes[d] || std::fabs(ijk[size_t(d)] - double(k)) > 1e-9) {
            diag.error(pr.where("node"), pr.path("node"),
                       "node index " + format_number(ijk[size_t(d)]) + " along " + "xyz"[d] +
                           " is not an integer in [0, " + std::to_string(sim_->grid.nodes[d] - 1) +
                           "]");
          }
          idx += size_t(std::max(0L, k)) * size_t(sim_->grid.node_stride[d]);
        }
        probe.node = idx;
      } else {
        probe.set = sim_->set_param(pr, "set", diag);
        if (probe.set < 0) continue;
        const Particles<D>& ps = sim_->sets[size_t(probe.set)].particles;
        for (const auto& name : probe.fields)
          if (!derived_field(name) && !ps.has(ps.find(name)))
            diag.error(pr.where("fields"), pr.path("fields"),
                       "particle set '" + sim_->sets[size_t(probe.set)].name +
                           "' does not store field '" + name + "'");
        if (ps.size() == 0) {
          diag.error(pr.where("set"), pr.path("set"), "the particle set has no particles");
          continue;
        }
        const auto& target = pr.vec("particle_near");
        double best = 1e300;
        for (size_t i = 0; i < ps.size(); ++i) {
          double r2 = 0;
          for (int d = 0; d < D; ++d) {
            double dx = ps.col(ps.position, d)[i] - target[size_t(d)];
            r2 += dx * dx;
          }
          if (r2 < best) best = r2, probe.particle_id = ps.id[i];
        }
      }
      probes_.push_back(std::move(probe));
    }
    for (size_t i = 0; i < probes_.size(); ++i)
      for (size_t j = 0; j < i; ++j)
        if (probes_[i].name == probes_[j].name)
          diag.error(cfg_.params.where("probes"), "probes." + std::to_string(i) + ".name",
                     "duplicate probe name '" + probes_[i].name + "'");
    if (need_disp) {
      initial_position_ = sim_->request_field(
          {"initial_position", D, "m", "position at t = 0", Particles<D>::axis_names()});
      displacement_ = sim_->request_field(
          {"displacement", D, "m", "position minus initial position", Particles<D>::axis_names()});
      for (auto& s : sim_->sets) {
        Particles<D>& ps = s.particles;
        for (int d = 0; d < D; ++d)
          std::copy(ps.col(ps.position, d), ps.col(ps.position, d) + ps.size(),
                    ps.col(initial_position_, d));
      }
      for (const auto& n : names)
        if (n == "displacement") frame_fields_.push_back(displacement_);
    }
  }

  std::string prepare_directory() {
    dir_ = opt_.out_dir.empty() ? fs::path("results") / cfg_.name : fs::path(opt_.out_dir);
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

  void refresh_derived() {
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

  void open_outputs() {
    writer_ =
        Registry::instance().create<Writer, D>(cfg_.params.section("output").section("writer"));
    writer_->open(dir_.string(), *sim_, frame_fields_);
    history_.open(dir_ / "history.csv");
    history_.out() << "step,time,dt,kinetic_energy,strain_energy,gravity_energy,total_energy";
    for (int d = 0; d < D; ++d)
      history_.out() << ",momentum_"
                     << "xyz"[d];
    if (exchanges_particles()) history_.out() << ",particles,mass_created,mass_removed";
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

  void sample_probes(bool force) {
    for (auto& pr : probes_) {
      if (!force && sim_->step % pr.every != 0) continue;
      auto& o = pr.csv.out();
      o << sim_->step << "," << sim_->time;
      if (pr.on_node) {
        for (const auto& f : pr.fields)
          for (const auto& g : sim_->scheme->grid_fields())
            if (g.name == f)
              for (int c = 0; c < g.components; ++c)
                o << "," << g.base[pr.node * size_t(g.stride) + size_t(g.offset + c)];
      } else {
        const ParticleSet<D>& set = sim_->sets[size_t(pr.set)];
        const Particles<D>& p = set.particles;
        size_t i = set.index_of(pr.particle_id);
        for (const auto& f : pr.fields) {
          if (f == "displacement") {
            for (int d = 0; d < D; ++d)
              o << "," << p.col(p.position, d)[i] - p.col(initial_position_, d)[i];
            continue;
          }
          int h = p.find(f);
          for (int c = 0; c < p.info(h).components; ++c) o << "," << p.col(h, c)[i];
        }
      }
      o << "\n";
    }
  }

  void write_history() {
    Energies e = sim_->energies();
    auto& o = history_.out();
    double strain = std::isnan(e.strain) ? 0.0 : e.strain;
    o << sim_->step << "," << sim_->time << "," << sim_->dt << "," << e.kinetic << "," << e.strain
      << "," << e.gravity << "," << e.kinetic + strain + e.gravity;
    for (double m : e.momentum) o << "," << m;
    if (exchanges_particles())
      o << "," << sim_->num_particles() << "," << sim_->mass_created << "," << sim_->mass_removed;
    o << "\n";
  }

  bool exchanges_particles() const { return !sim_->sources.empty() || !sim_->sinks.empty(); }

  void write_frame(const std::string& label) {
    refresh_derived();
    writer_->write(*sim_, label);
    ++frames_;
  }

  nlohmann::json base_summary() const {
    nlohmann::json s;
    s["loam_version"] = loam_version();
    s["git_commit"] = git_commit();
    s["config_file"] = cfg_.file;
    s["config"] = cfg_.params.to_json();
    s["dimension"] = D;
    s["particles"] = sim_->num_particles();
    nlohmann::json sets = nlohmann::json::object();
    for (const auto& set : sim_->sets) {
      std::vector<std::string> bodies;
      for (int b : set.bodies)
        bodies.push_back(sim_->bodies.size() > size_t(b) ? sim_->bodies[size_t(b)].name : "");
      double mass = 0, kinetic = 0;  // the particles' own (a scheme's second phase not included)
      const Particles<D>& P = set.particles;
      for (size_t i = 0; i < P.size(); ++i) {
        const double m = P.col(P.mass)[i];
        mass += m;
        for (int d = 0; d < D; ++d) kinetic += 0.5 * m * std::pow(P.col(P.velocity, d)[i], 2);
      }
      sets[set.name] = {{"particles", set.size()},
                        {"mass", mass},
                        {"kinetic_energy", kinetic},
                        {"bodies", bodies},
                        {"bytes_per_particle", set.particles.bytes_per_particle()}};
    }
    s["sets"] = sets;
    s["cells"] = sim_->grid.num_cells;
    s["nodes"] = sim_->grid.num_nodes;
    s["shape_function"] = sim_->config.section("shape_function").type();
    s["scheme"] = sim_->config.section("scheme").type();
    size_t bytes = 0;
    for (const auto& set : sim_->sets) bytes += set.size() * set.particles.bytes_per_particle();
    s["bytes_per_particle"] = sim_->num_particles() ? bytes / sim_->num_particles()
                                                    : sim_->sets[0].particles.bytes_per_particle();
    return s;
  }

  RunResult loop() {
    RunResult res;
    Simulation<D>& sim = *sim_;
    const Params& out = cfg_.params.section("output");
    const long every_steps = out.has("every_steps") ? long(out.integer("every_steps")) : 0;
    double every_time = out.has("every_time") ? out.real("every_time") : 0;
    if (!every_steps && every_time <= 0) every_time = sim.end_time / 20;
    const long history_every = long(out.integer("history_every"));
    double next_frame_time = every_time;
    const bool files = opt_.write_output;
    if (files) {
      open_outputs();
      write_frame("");
      write_history();
      sample_probes(true);
    }
    Energies e0 = sim.energies();
    double dt_min = 1e300, dt_max = 0;
    std::string failure;
    auto t0 = Clock::now(), last_report = t0;
    long steps_at_report = 0;
    const double t_end = sim.end_time;
    const double min_dt_ratio = cfg_.params.section("time").real("min_dt_ratio");
    double dt_first = 0;
    while (sim.time < t_end * (1 - 1e-12) && (opt_.max_steps < 0 || sim.step < opt_.max_steps)) {
      double dt = sim.stable_dt();
      if (dt_first == 0) dt_first = dt;
      if (dt < min_dt_ratio * dt_first) {
        failure = "the stable time step collapsed to " + format_number(dt) + " s, below " +
                  "time.min_dt_ratio = " + format_number(min_dt_ratio) + " of the first step's " +
                  format_number(dt_first) + " s (largest particle speed " +
                  format_number(sim.max_speed) +
                  " m/s): a wave or particle speed exploded; remedies: scheme.update: musl, a "
                  "smaller time.cfl, a smooth shape function (gimp, bspline2, cpdi)";
        break;
      }
      if (sim.time + dt > t_end) dt = t_end - sim.time;
      dt_min = std::min(dt_min, dt);
      dt_max = std::max(dt_max, dt);
      // Whether the step ends at a frame or the end (the particles are then always checked).
      const long next_step = sim.step + 1;
      const double next_time = sim.time + dt;
      const bool frame_due =
          files && ((every_steps && next_step % every_steps == 0) ||
                    (every_time > 0 && next_time >= next_frame_time * (1 - 1e-9)));
      const bool last = next_time >= t_end * (1 - 1e-12) || next_step == opt_.max_steps;
      if (!sim.advance(dt, frame_due || last)) {
        failure = sim.failure;
        break;
      }
      if (sim.step >= sim.max_steps && sim.time < t_end * (1 - 1e-12)) {
        failure = "time.max_steps = " + std::to_string(sim.max_steps) +
                  " reached before t = " + format_number(t_end) + " s; the time step fell to " +
                  format_number(dt) + " s (it was " + format_number(dt_max) + " s at most)";
        break;
      }
      if (sim.reference) sim.reference->sample(sim);
      if (files) {
        sample_probes(last);
        if (frame_due || last) {
          write_frame("");
          while (every_time > 0 && next_frame_time <= sim.time * (1 + 1e-9))
            next_frame_time += every_time;
        }
        if ((history_every > 0 && sim.step % history_every == 0) ||
            (history_every == 0 && (frame_due || last)))
          write_history();
      }
      auto now = Clock::now();
      if (!opt_.quiet && std::chrono::duration<double>(now - last_report).count() > 3.0) {
        double el = std::chrono::duration<double>(now - t0).count();
        double sps = double(sim.step - steps_at_report) /
                     std::chrono::duration<double>(now - last_report).count();
        double frac = sim.time / t_end;
        double eta = frac > 0 ? el * (1 - frac) / frac : 0;
        spdlog::info("{:5.1f}%  t = {:.4g} s  step {}  {:.3g} steps/s  ETA {:.0f} s", 100 * frac,
                     sim.time, sim.step, sps, eta);
        last_report = now;
        steps_at_report = sim.step;
      }
    }
    double wall = std::chrono::duration<double>(Clock::now() - t0).count();
    res.summary = base_summary();
    res.summary["status"] = failure.empty() ? "ok" : "unstable";
    res.summary["steps"] = sim.step;
    res.summary["end_time"] = sim.time;
    res.summary["wall_seconds"] = wall;
    res.summary["threads"] = sim.threads;
    res.summary["particle_steps_per_second"] =
        wall > 0 ? double(sim.num_particles()) * double(sim.step) / wall : 0.0;
    res.summary["dt_min"] = dt_min < 1e300 ? dt_min : 0.0;
    res.summary["dt_max"] = dt_max;
    res.summary["frames"] = frames_;
    if (sim.profiling) res.summary["profile_seconds"] = sim.profile;
    Energies e1 = sim.energies();
    auto energy_json = [](const Energies& e) {
      return nlohmann::json{
          {"kinetic", e.kinetic},
          {"strain", std::isnan(e.strain) ? nlohmann::json() : nlohmann::json(e.strain)},
          {"gravity", e.gravity},
          {"momentum", e.momentum}};
    };
    // Sources and sinks: counts and the mass balance (round-off when nothing is lost).
    const double mass_now = sim.total_mass();
    res.summary["particles_created"] = sim.created;
    res.summary["particles_removed"] = sim.removed;
    res.summary["mass"] = {
        {"initial", sim.initial_mass},
        {"final", mass_now},
        {"created", sim.mass_created},
        {"removed", sim.mass_removed},
        {"balance", mass_now + sim.mass_removed - sim.mass_created - sim.initial_mass}};
    res.summary["energy_initial"] = energy_json(e0);
    res.summary["energy_final"] = energy_json(e1);
    if (sim.reference) {
      nlohmann::json v = nlohmann::json::object();
      for (const auto& [k, x] : sim.reference->metrics(sim)) v[k] = x;
      v["reference"] = cfg_.params.section("verify").type();
      res.summary["verify"] = v;
    }
    if (!failure.empty()) {
      res.exit_code = 3;
      res.message =
          "loam: error: unstable run at step " + std::to_string(sim.step) +
          ", t = " + format_number(sim.time) + " s: " + failure +
          (files ? "; the state at detection was written as the last frame ('failed')" : "") + "\n";
      res.summary["failure"] = res.message;
      if (files) write_frame("failed");
    }
    if (files) {
      if (!failure.empty()) write_history();
      history_.close();
      for (auto& pr : probes_) pr.csv.close();
      writer_->close();
      fs::path tmp = dir_ / "summary.json.tmp";
      {
        std::ofstream js(tmp);
        js << res.summary.dump(2) << "\n";
      }
      fs::rename(tmp, dir_ / "summary.json");
    }
    if (!opt_.quiet && failure.empty())
      spdlog::info(
          "done: {} steps, {} particles, {:.3g} s wall, {:.3g} M particle-steps/s on {} thread(s)",
          sim.step, sim.num_particles(), wall,
          res.summary["particle_steps_per_second"].get<double>() / 1e6, sim.threads);
    return res;
  }
};

template <int D>
RunResult run_dim(const LoadedConfig& cfg, const RunOptions& opt, bool check_only) {
  Run<D> run(cfg, opt);
  return run.execute(check_only);
}

RunResult dispatch(const LoadedConfig& cfg, const RunOptions& opt, bool check_only) {
  switch (cfg.dimension) {
    case 1:
      return run_dim<1>(cfg, opt, check_only);
    case 2:
      return run_dim<2>(cfg, opt, check_only);
    case 3:
      return run_dim<3>(cfg, opt, check_only);
  }
  RunResult r;
  r.exit_code = 2;
  r.message = "loam: error: the grid dimension could not be determined\n";
  return r;
}

}  // namespace

RunResult run_config(const LoadedConfig& cfg, const RunOptions& opt) {
  return dispatch(cfg, opt, false);
}
RunResult check_config(const LoadedConfig& cfg) {
  return dispatch(cfg, RunOptions{}, true);
}

int run_file(const std::string& file, const RunOptions& opt) {
  Diagnostics diag;
  LoadedConfig cfg = load_config(file, opt.overrides, diag);
  if (!diag.ok()) {
    fputs(diag.format().c_str(), stderr);
    return 2;
  }
  RunResult r = run_config(cfg, opt);
  if (!r.message.empty()) fputs(r.message.c_str(), stderr);
  return r.exit_code;
}

}  // namespace loam
