// Running a validated configuration: the time loop (time step, stops, when frames and history are
// due, progress), summary.json, and the entry points run_file, run_config and check_config. The
// output files are written in run_output.cpp; Run<D> is declared in run.hpp.
#include "runner.hpp"

#include <omp.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "interrupt.hpp"
#include "run.hpp"
#include "simulation.hpp"

namespace loam {

namespace {

using Clock = std::chrono::steady_clock;

/// A reference's time series as CSV (a column per series, full precision), written under a
/// temporary name and renamed, like summary.json.
void write_series_csv(const std::filesystem::path& file,
                      const std::vector<std::pair<std::string, std::vector<double>>>& series) {
  const auto tmp = std::filesystem::path(file.string() + ".tmp");
  {
    std::ofstream out(tmp);
    size_t rows = 0;
    for (size_t c = 0; c < series.size(); ++c) {
      out << (c ? "," : "") << series[c].first;
      rows = std::max(rows, series[c].second.size());
    }
    out << "\n";
    char buf[32];
    for (size_t r = 0; r < rows; ++r) {
      for (size_t c = 0; c < series.size(); ++c) {
        const auto& v = series[c].second;
        std::snprintf(buf, sizeof buf, "%.12g", r < v.size() ? v[r] : std::nan(""));
        out << (c ? "," : "") << buf;
      }
      out << "\n";
    }
  }
  std::filesystem::rename(tmp, file);
}

}  // namespace

namespace detail {

template <int D>
RunResult Run<D>::execute(bool check_only) {
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

template <int D>
nlohmann::json Run<D>::base_summary() const {
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
    double kinetic = 0;  // the particles' own (a scheme's second phase not included)
    const Particles<D>& P = set.particles;
    for (size_t i = 0; i < P.size(); ++i)
      for (int d = 0; d < D; ++d)
        kinetic += 0.5 * P.col(P.mass)[i] * std::pow(P.col(P.velocity, d)[i], 2);
    sets[set.name] = {{"particles", set.size()},
                      {"mass", set.mass()},
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

template <int D>
RunResult Run<D>::loop() {
  RunResult res;
  InterruptGuard guard;  // SIGINT, SIGTERM: stop after the current step; SIGXFSZ ignored
  Simulation<D>& sim = *sim_;
  const Params& out = cfg_.params.section("output");
  const long every_steps = out.has("every_steps") ? long(out.integer("every_steps")) : 0;
  double every_time = out.has("every_time") ? out.real("every_time") : 0;
  if (!every_steps && every_time <= 0) every_time = sim.end_time / 20;
  const long history_every = long(out.integer("history_every"));
  double next_frame_time = every_time;
  const bool files = opt_.write_output;
  // A file that cannot be written (WriteError, a failed rename) stops the run with exit 4.
  std::string write_error;
  auto guarded = [&](auto&& write) {
    if (!write_error.empty()) return;
    try {
      write();
    } catch (const WriteError& e) {
      write_error = e.what();
    } catch (const fs::filesystem_error& e) {
      write_error = "cannot write " + e.path1().string() + ": " + e.code().message();
    }
  };
  if (files)
    guarded([&] {
      open_outputs();
      write_frame("");
      write_history();
      sample_probes(true);
    });
  Energies e0 = sim.energies();
  double dt_min = 1e300, dt_max = 0;
  std::string failure;
  auto t0 = Clock::now(), last_report = t0;
  long steps_at_report = 0;
  const double t_end = sim.end_time;
  const double min_dt_ratio = cfg_.params.section("time").real("min_dt_ratio");
  double dt_first = 0;
  int interrupted = 0;                           // the signal that stopped the run (InterruptGuard)
  long frame_step = 0, history_step = 0;         // the steps of the last frame and history row
  if (sim.keep_last_good) sim.save_last_good();  // t = 0: it passed the set-up checks
  while (write_error.empty() && sim.time < t_end * (1 - 1e-12) &&
         (opt_.max_steps < 0 || sim.step < opt_.max_steps)) {
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
    const bool frame_due = files && ((every_steps && next_step % every_steps == 0) ||
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
    if (files)
      guarded([&] {
        sample_probes(last);
        if (frame_due || last) {
          write_frame("");
          frame_step = sim.step;
          while (every_time > 0 && next_frame_time <= sim.time * (1 + 1e-9))
            next_frame_time += every_time;
        }
        if ((history_every > 0 && sim.step % history_every == 0) ||
            (history_every == 0 && (frame_due || last))) {
          write_history();
          history_step = sim.step;
        }
      });
    if (!write_error.empty()) break;
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
    if ((interrupted = InterruptGuard::requested()) != 0) break;
  }
  if (interrupted && files)  // the state after the last complete step, as a regular frame
    guarded([&] {
      if (frame_step != sim.step) write_frame("");
      sample_probes(true);
      if (history_step != sim.step) write_history();
    });
  double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  res.summary = base_summary();
  res.summary["status"] = !failure.empty() ? "unstable" : interrupted ? "interrupted" : "ok";
  if (interrupted) res.summary["interrupted_by"] = signal_name(interrupted);
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
  res.summary["verify"] = nlohmann::json::object();  // always there: empty without a reference
  if (sim.reference) {
    nlohmann::json v = nlohmann::json::object();
    for (const auto& [k, x] : sim.reference->metrics(sim)) v[k] = x;
    v["reference"] = cfg_.params.section("verify").type();
    const auto series = sim.reference->series();
    for (const auto& [name, values] : series) v["series"][name] = values;
    res.summary["verify"] = v;
    if (files && !series.empty()) write_series_csv(dir_ / "verify.csv", series);
  }
  if (!failure.empty()) {
    res.exit_code = 3;
    std::string written;
    if (files) {
      // The last state that passed the check as the last regular frame (unless it is one
      // already), then the state at detection as 'failed'.
      const auto& good = sim.last_good;
      if (good.step >= 0) {
        if (good.step != frame_step) {
          sim.swap_last_good();
          guarded([&] { write_frame(""); });
          sim.swap_last_good();
        }
        res.summary["last_good"] = {{"step", good.step}, {"time", good.time}};
        written = "; the last state that passed the check (step " + std::to_string(good.step) +
                  ", t = " + format_number(good.time) + " s) is the last regular frame";
      }
      guarded([&] { write_frame("failed"); });
      written += "; the state at detection was written as the frame labelled 'failed'";
    }
    res.message = "loam: error: unstable run at step " + std::to_string(sim.step) +
                  ", t = " + format_number(sim.time) + " s: " + failure + written + "\n";
    res.summary["failure"] = res.message;
  }
  if (interrupted && failure.empty()) {
    res.exit_code = 128 + interrupted;
    res.message = "loam: interrupted by " + signal_name(interrupted) + " at step " +
                  std::to_string(sim.step) + ", t = " + format_number(sim.time) + " s" +
                  (files ? ": the last complete step was written as the last frame, with the "
                           "history, probes and summary.json (status: interrupted)"
                         : "") +
                  "\n";
  }
  if (files) {
    guarded([&] {
      if (!failure.empty()) write_history();
      history_.close();
      for (auto& pr : probes_) pr.csv.close();
      writer_->close();
    });
    if (!write_error.empty()) {
      // Keep what was written: the history and probe rows so far are renamed to their names.
      history_.close(false);
      for (auto& pr : probes_) pr.csv.close(false);
      res.exit_code = 4;
      res.message = "loam: error: " + write_error + "; the run stopped at step " +
                    std::to_string(sim.step) + ", t = " + format_number(sim.time) +
                    " s (the frames, history and probes written before are intact)\n";
      res.summary["status"] = "write_failed";
      res.summary["write_error"] = write_error;
    }
    if (write_error.empty()) {
      guarded([&] { write_summary(res.summary); });
      if (!write_error.empty()) {  // only summary.json failed
        res.exit_code = 4;
        res.message += "loam: error: " + write_error + "\n";
      }
    } else {
      try {  // the summary with status write_failed, if the disk still takes it
        write_summary(res.summary);
      } catch (const std::exception&) {
      }
    }
  }
  if (!opt_.quiet && failure.empty() && !interrupted)
    spdlog::info(
        "done: {} steps, {} particles, {:.3g} s wall, {:.3g} M particle-steps/s on {} thread(s)",
        sim.step, sim.num_particles(), wall,
        res.summary["particle_steps_per_second"].get<double>() / 1e6, sim.threads);
  return res;
}

}  // namespace detail

namespace {

using detail::Run;

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
