// Running a validated configuration: the time loop (time step, stops, when frames and history are
// due, progress), summary.json, and the entry points run_file, run_config and check_config. The
// output files are written in run_output.cpp; Run<D> is declared in run.hpp.
#include "runner.hpp"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "checkpoint.hpp"
#include "cores.hpp"
#include "interrupt.hpp"
#include "run.hpp"
#include "run_report.hpp"
#include "simulation.hpp"

namespace loam {

namespace {

using Clock = std::chrono::steady_clock;

/// A reference's time series as CSV (a column per series, full precision), written whole or not
/// at all, like summary.json.
void write_series_csv(const std::filesystem::path& file,
                      const std::vector<std::pair<std::string, std::vector<double>>>& series) {
  std::ostringstream out;
  {
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
  write_file_atomically(file.string(), out.str());
}

nlohmann::json energy_json(const Energies& e) {
  return nlohmann::json{
      {"kinetic", e.kinetic},
      {"strain", std::isnan(e.strain) ? nlohmann::json() : nlohmann::json(e.strain)},
      {"gravity", e.gravity},
      {"momentum", e.momentum}};
}

nlohmann::json balance_json(const EnergyBalance& b) {
  return nlohmann::json{{"dissipation_material", b.material},
                        {"dissipation_damping", b.damping},
                        {"dissipation_transfer", b.transfer},
                        {"dissipation_drag", b.drag},
                        {"dissipation_contact", b.contact},
                        {"work_loads", b.loads},
                        {"work_boundaries", b.boundaries},
                        {"energy_carried", b.carried},
                        {"balance", b.balance},
                        {"largest_term", b.largest}};
}

}  // namespace

namespace detail {

template <int D>
RunResult Run<D>::execute(bool check_only) {
  RunResult res;
  Diagnostics diag;
  int threads = opt_.threads > 0 ? opt_.threads : default_threads();
  sim_ = std::make_unique<Simulation<D>>(cfg_.params, threads, diag);
  if (sim_->model_checked) check_outputs(diag);
  if (sim_->model_checked) check_strength_reduction(diag);
  if (sim_) sim_->profiling = opt_.profile;
  if (!diag.ok()) {
    res.exit_code = 2;
    res.message = diag.format();
    return res;
  }
  res.warnings = run_warnings(cfg_, diag);
  if (check_only) {
    res.summary = base_summary();
    return res;
  }
  if (opt_.report && !opt_.quiet && sim_->ranks->root()) fputs(res.warnings.c_str(), stderr);
  const Params& output = cfg_.params.section("output");
  if (output.has("checkpoint") && (output.section("checkpoint").has("every_steps") ||
                                   output.section("checkpoint").has("every_wall_seconds"))) {
    const Params& c = output.section("checkpoint");
    checkpoint_every_ = c.has("every_steps") ? long(c.integer("every_steps")) : 0;
    checkpoint_wall_ = c.has("every_wall_seconds") ? c.real("every_wall_seconds") : 0;
    checkpoint_keep_ = c.has("keep") ? int(c.integer("keep")) : 2;
    const std::string problem = checkpoint_problem();
    if (!problem.empty()) {
      res.exit_code = 2;
      Diagnostics d;
      d.error(c.where(), c.path(), problem);
      res.message = d.format();
      return res;
    }
  }
  if (!opt_.resume.empty()) {
    const std::string err = find_resume_checkpoint();
    if (!err.empty()) {
      res.exit_code = 2;
      res.message = "loam: error: " + err + "\n";
      return res;
    }
    return loop();
  }
  if (opt_.write_output) {
    // Under mpirun the first rank prepares the directory and the others wait for its verdict.
    const Ranks<D>& ranks = *sim_->ranks;
    std::string err = ranks.root() ? prepare_directory() : (dir_ = output_directory(), "");
    if (ranks.distributed()) err = ranks.first_message(err);
    if (!err.empty()) {
      res.exit_code = 2;
      res.message = "loam: error: " + err + "\n";
      return res;
    }
  }
  return loop();
}

// ------------------------------------------------------------------ checkpoints
template <int D>
nlohmann::json Run<D>::base_summary() const {
  nlohmann::json s;
  s["loam_version"] = loam_version();
  s["git_commit"] = git_commit();
  s["config_file"] = cfg_.file;
  s["config"] = cfg_.params.to_json();
  s["dimension"] = D;
  const double particles = global_particles();
  s["particles"] = size_t(particles);
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
    double totals[3] = {double(set.size()), set.mass(), kinetic};  // over the ranks
    sim_->ranks->sum(totals, 3);
    sets[set.name] = {{"particles", size_t(totals[0])},
                      {"mass", totals[1]},
                      {"kinetic_energy", totals[2]},
                      {"bodies", bodies},
                      {"bytes_per_particle", set.particles.bytes_per_particle()}};
  }
  s["sets"] = sets;
  s["cells"] = sim_->grid.num_cells;
  s["nodes"] = sim_->grid.num_nodes;
  s["shape_function"] = sim_->config.section("shape_function").type();
  s["scheme"] = sim_->config.section("scheme").type();
  double bytes = 0;
  for (const auto& set : sim_->sets)
    bytes += double(set.size()) * double(set.particles.bytes_per_particle());
  sim_->ranks->sum(&bytes, 1);
  s["bytes_per_particle"] =
      particles > 0 ? size_t(bytes / particles) : sim_->sets[0].particles.bytes_per_particle();
  if (!sim_->reactions.empty()) s["reactions"] = reaction_summary();
  if (!sim_->rigid_records.empty()) s["rigid_bodies"] = rigid_summary();
  return s;
}

/// Per mechanical condition the force it applied in the last step and the least and largest
/// value of each component over the run's steps (N; per metre in 2D, per square metre in 1D),
/// per phase: "force", "min", "max", and for the water of a two-phase scheme "water_force", ...
template <int D>
nlohmann::json Run<D>::reaction_summary() const {
  const Reactions<D>& r = sim_->reactions;
  nlohmann::json out = nlohmann::json::object();
  for (size_t c = 0; c < r.names().size(); ++c) {
    nlohmann::json e;
    for (int k = 0; k < sim_->scheme->phases(); ++k) {
      const std::string pre = k ? "water_" : "";
      const size_t at = size_t(k * D);
      e[pre + "force"] = std::vector<double>(r.force(c) + at, r.force(c) + at + D);
      e[pre + "min"] = std::vector<double>(r.lowest(c) + at, r.lowest(c) + at + D);
      e[pre + "max"] = std::vector<double>(r.highest(c) + at, r.highest(c) + at + D);
    }
    out[r.names()[c]] = e;
  }
  return out;
}

/// Per rigid body under contact its displacement (m), rotation (rad) and moment (N m; per metre
/// in 2D) after the last step, and the least and largest moment over the run
/// (framework/rigid_records.hpp).
template <int D>
nlohmann::json Run<D>::rigid_summary() const {
  using Records = RigidRecords<D>;
  const Records& r = sim_->rigid_records;
  nlohmann::json out = nlohmann::json::object();
  for (size_t c = 0; c < r.names().size(); ++c) {
    const double* v = r.values(c);
    auto part = [&](int at, int n) { return std::vector<double>(v + at, v + at + n); };
    out[r.names()[c]] = {{"displacement", part(Records::kDisplacement, D)},
                         {"rotation", part(Records::kRotation, Records::R)},
                         {"moment", part(Records::kMoment, Records::R)},
                         {"moment_min", part(Records::kMomentLow, Records::R)},
                         {"moment_max", part(Records::kMomentHigh, Records::R)}};
  }
  return out;
}

template <int D>
void Run<D>::frame_interval(int k, long& every_steps, double& every_time) const {
  const Params& out = cfg_.params.section("output");
  every_steps = out.has("every_steps") ? long(out.integer("every_steps")) : 0;
  every_time = out.has("every_time") ? out.real("every_time") : 0;
  if (!every_steps && every_time <= 0) every_time = sim_->end_time / 20;
  for (int j = 0; j <= k && j < int(sim_->stages.size()); ++j)
    if (sim_->stages[size_t(j)].sets_output) {
      every_steps = sim_->stages[size_t(j)].every_steps;
      every_time = sim_->stages[size_t(j)].every_time;
    }
}

template <int D>
void Run<D>::report_end(const nlohmann::json& summary, const std::string& out_dir, double particles,
                        double wall) const {
  const Simulation<D>& sim = *sim_;
  if (opt_.quiet) {
    std::printf("%s\n", run_report_line(summary, out_dir).c_str());
    return;
  }
  spdlog::info(
      "done: {} steps, {} particles, {:.3g} s wall, {:.3g} M particle-steps/s on {} thread(s){}",
      sim.step, particles, wall, summary["particle_steps_per_second"].get<double>() / 1e6,
      sim.threads,
      sim.ranks->distributed() ? fmt::format(" x {} MPI rank(s)", sim.ranks->size())
                               : std::string());
  for (const std::string& line : run_report(summary, out_dir)) spdlog::info("  {}", line);
}

template <int D>
nlohmann::json Run<D>::stage_record(const std::string& status) {
  Simulation<D>& sim = *sim_;
  const Stage<D>& st = sim.stages[size_t(ls_.stage)];
  nlohmann::json r;
  r["name"] = st.name;
  r["status"] = status;
  r["start_time"] = ls_.stage_start;
  r["end_time"] = sim.time;
  r["steps"] = sim.step - ls_.stage_step0;
  if (st.until_static) {
    r["static"] = status == "static";
    r["static_window"] = ls_.static_window;
  }
  r["max_speed"] = sim.max_speed;  // over the ranks (Simulation::advance)
  if (st.until_static) r["motion_speed"] = sim.motion_speed;  // over the ranks already
  // The largest displacement since the last reset (the output's displacement reference).
  r["max_displacement"] = sim.ranks->max(largest_displacement());
  r["energy"] = energy_json(sim.energies());
  if (sim.reference) {
    nlohmann::json v = nlohmann::json::object();
    for (const auto& [key, x] : sim.reference->metrics(sim)) v[key] = x;
    r["verify"] = v;
  }
  return r;
}

template <int D>
void Run<D>::profile_by_rank(nlohmann::json& summary) const {
  std::vector<double> mine;
  for (const auto& [phase, seconds] : sim_->profile) mine.push_back(seconds);
  const std::vector<double> all = sim_->ranks->gather(mine);
  if (sim_->ranks->rank() != 0) return;
  if (all.size() != size_t(sim_->ranks->size()) * mine.size()) {
    summary["profile_seconds_by_rank"] = "the ranks timed different phases";
    return;
  }
  nlohmann::json by_rank = nlohmann::json::array();
  for (size_t r = 0; r * mine.size() < all.size(); ++r) {
    nlohmann::json phases;
    size_t k = 0;
    for (const auto& [phase, seconds] : sim_->profile) phases[phase] = all[r * mine.size() + k++];
    by_rank.push_back(phases);
  }
  summary["profile_seconds_by_rank"] = by_rank;
}

template <int D>
template <class F>
void Run<D>::guarded(F&& write) {
  // A file that cannot be written (WriteError, a failed rename) stops the run with exit 4.
  // Serially the outputs after a failed one are skipped; under mpirun every rank still makes
  // every output's collective calls (a frame's gather, the history's energies, the probes'
  // gather), so that no rank waits for one that gave up; the ranks agree on the error after.
  if (!end_.write_error.empty() && !sim_->ranks->distributed()) return;
  try {
    write();
  } catch (const WriteError& e) {
    if (end_.write_error.empty()) end_.write_error = e.what();
  } catch (const fs::filesystem_error& e) {
    if (end_.write_error.empty())
      end_.write_error = "cannot write " + e.path1().string() + ": " + e.code().message();
  }
}

template <int D>
void Run<D>::start_loop() {
  Simulation<D>& sim = *sim_;
  const bool resuming = !resume_file_.empty();
  if (resuming)
    restore_checkpoint();
  else
    ls_.e0 = sim.energies();
  schedule_.history_every = long(cfg_.params.section("output").integer("history_every"));
  schedule_.min_dt_ratio = cfg_.params.section("time").real("min_dt_ratio");
  frame_interval(int(ls_.stage), schedule_.every_steps, schedule_.every_time);
  if (!resuming) ls_.next_frame_time = schedule_.every_time;
  if (opt_.write_output)
    guarded([&] {
      open_outputs(resuming ? sim.step : -1);
      if (resuming) {
        writer_->restore_state(resume_writer_state_);
      } else {
        write_frame("");
        write_history();
        sample_probes(true);
      }
    });
  schedule_.last_checkpoint = Clock::now();
  progress_.start = progress_.last = Clock::now();
  progress_.steps = 0;
  keep_good_image_ = opt_.write_output && sim.keep_last_good && checkpointing();
}

template <int D>
void Run<D>::begin_stage(int k) {
  Simulation<D>& sim = *sim_;
  const Stage<D>& stage = sim.stages[size_t(k)];
  sim.begin_stage(k);
  ls_.stage = k;
  ls_.stage_start = sim.time;
  ls_.stage_step0 = sim.step;
  ls_.static_since = -1;
  ls_.static_window = stage.static_window > 0 ? stage.static_window : default_static_window();
  if (stage.sets_output) {
    frame_interval(k, schedule_.every_steps, schedule_.every_time);
    ls_.next_frame_time = sim.time + schedule_.every_time;
  }
}

template <int D>
void Run<D>::run_stages() {
  Simulation<D>& sim = *sim_;
  const int num_stages = int(sim.stages.size());
  bool within_stage = !resume_file_.empty();  // resumed within stage ls_.stage: it has begun
  for (int k = within_stage ? int(ls_.stage) : 0; k < num_stages; ++k) {
    if (!within_stage) begin_stage(k);
    within_stage = false;
    // The state at the stage's start (or the checkpoint) passed the checks. With checkpoints,
    // the run's own state is kept beside the particles' (good_image_), for a checkpoint of the
    // last good state.
    if (sim.keep_last_good) sim.save_last_good();
    if (keep_good_image_) good_image_ = checkpoint_image();
    const Stage<D>& stage = sim.stages[size_t(k)];
    sim.track_motion = stage.until_static;
    const double t_end = ls_.stage_start + stage.duration;
    bool reached_static = false;
    while (end_.write_error.empty() && sim.time < t_end * (1 - 1e-12) &&
           (opt_.max_steps < 0 || sim.step < opt_.max_steps))
      if (!take_step(stage, t_end, reached_static)) break;
    end_.budget =
        opt_.max_steps >= 0 && sim.step >= opt_.max_steps && sim.time < t_end * (1 - 1e-12);
    const bool stopped =
        !end_.failure.empty() || end_.interrupted || !end_.write_error.empty() || end_.budget;
    if (!stage.params.path().empty()) end_stage(k, stopped, reached_static);
    if (stopped || !end_.stopped_by_stage.empty()) break;
  }
}

template <int D>
double Run<D>::next_dt(double t_end) {
  Simulation<D>& sim = *sim_;
  const double min_dt_ratio = schedule_.min_dt_ratio;
  double dt = sim.stable_dt();
  if (ls_.dt_first == 0) ls_.dt_first = dt;
  if (dt < min_dt_ratio * ls_.dt_first) {
    end_.failure = "the stable time step collapsed to " + format_number(dt) + " s, below " +
                   "time.min_dt_ratio = " + format_number(min_dt_ratio) + " of the first step's " +
                   format_number(ls_.dt_first) + " s (largest particle speed " +
                   format_number(sim.max_speed) +
                   " m/s): a wave or particle speed exploded; remedies: scheme.update: musl, a "
                   "smaller time.cfl, a smooth shape function (gimp, bspline2, cpdi)";
    return 0;
  }
  if (sim.time + dt > t_end) dt = t_end - sim.time;
  ls_.dt_min = std::min(ls_.dt_min, dt);
  ls_.dt_max = std::max(ls_.dt_max, dt);
  return dt;
}

template <int D>
typename Run<D>::Due Run<D>::outputs_due(double dt, double t_end) {
  Simulation<D>& sim = *sim_;
  const bool files = opt_.write_output;
  Due due;
  const long next_step = sim.step + 1;
  const double next_time = sim.time + dt;
  due.frame =
      files && ((schedule_.every_steps && next_step % schedule_.every_steps == 0) ||
                (schedule_.every_time > 0 && next_time >= ls_.next_frame_time * (1 - 1e-9)));
  due.last = next_time >= t_end * (1 - 1e-12) || next_step == opt_.max_steps;
  // A checkpoint is written only of a state that passed the check. Under mpirun every rank
  // writes its file of the same step: the wall-clock interval is up when it is on any rank.
  bool wall_due = checkpoint_wall_ > 0 &&
                  std::chrono::duration<double>(Clock::now() - schedule_.last_checkpoint).count() >=
                      checkpoint_wall_;
  if (sim.ranks->distributed() && checkpoint_wall_ > 0)
    wall_due = sim.ranks->max(int(wall_due)) != 0;
  due.checkpoint = files && !due.last &&
                   ((checkpoint_every_ > 0 && next_step % checkpoint_every_ == 0) || wall_due);
  return due;
}

template <int D>
bool Run<D>::take_step(const Stage<D>& stage, double t_end, bool& reached_static) {
  Simulation<D>& sim = *sim_;
  const double dt = next_dt(t_end);
  if (!end_.failure.empty()) return false;
  Due due = outputs_due(dt, t_end);
  if (!sim.advance(dt, due.frame || due.last || due.checkpoint)) {
    end_.failure = sim.failure;
    return false;
  }
  if (sim.step >= sim.max_steps && sim.time < sim.end_time * (1 - 1e-12)) {
    end_.failure = "time.max_steps = " + std::to_string(sim.max_steps) +
                   " reached before t = " + format_number(sim.end_time) +
                   " s; the time step fell to " + format_number(dt) + " s (it was " +
                   format_number(ls_.dt_max) + " s at most)";
    return false;
  }
  // until: static, judged on checked steps (a frame ends the stage there).
  if (stage.until_static && sim.checked_step == sim.step) {
    reached_static = at_rest(sim.time, sim.motion_speed, stage.static_speed, ls_.static_window,
                             ls_.static_since);
    due.last = due.last || reached_static;
  }
  if (sim.reference) sim.reference->sample(sim);
  if (opt_.write_output) write_due(due);
  if (sim.ranks->distributed()) end_.write_error = sim.ranks->first_message(end_.write_error);
  if (!end_.write_error.empty()) return false;
  report_progress();
  end_.interrupted = InterruptGuard::requested();
  if (sim.ranks->distributed())
    end_.interrupted = sim.ranks->max(end_.interrupted);  // every rank stops together
  return end_.interrupted == 0 && !reached_static;
}

template <int D>
void Run<D>::write_due(const Due& due) {
  Simulation<D>& sim = *sim_;
  guarded([&] { sample_probes(due.last); });
  if (due.frame || due.last)
    guarded([&] {
      write_frame("");
      ls_.frame_step = sim.step;
      while (schedule_.every_time > 0 && ls_.next_frame_time <= sim.time * (1 + 1e-9))
        ls_.next_frame_time += schedule_.every_time;
    });
  const long every = schedule_.history_every;
  if ((every > 0 && sim.step % every == 0) || (every == 0 && (due.frame || due.last)))
    guarded([&] {
      write_history();
      ls_.history_step = sim.step;
    });
  if (due.checkpoint && !due.last)  // not of a stage's end (static is known after it)
    guarded([&] {
      write_checkpoint(checkpoint_image());
      schedule_.last_checkpoint = Clock::now();
    });
  if (keep_good_image_ && sim.last_good.step == sim.step)
    guarded([&] { good_image_ = checkpoint_image(); });
}

template <int D>
void Run<D>::report_progress() {
  const Simulation<D>& sim = *sim_;
  const auto now = Clock::now();
  if (opt_.quiet || !opt_.report ||
      std::chrono::duration<double>(now - progress_.last).count() <= 3.0)
    return;
  const double el = std::chrono::duration<double>(now - progress_.start).count();
  const double sps = double(sim.step - progress_.steps) /
                     std::chrono::duration<double>(now - progress_.last).count();
  const double frac = sim.time / sim.end_time;
  const double eta = frac > 0 ? el * (1 - frac) / frac : 0;
  spdlog::info("{:5.1f}%  t = {:.4g} s  step {}  {:.3g} steps/s  ETA {:.0f} s", 100 * frac,
               sim.time, sim.step, sps, eta);
  progress_.last = now;
  progress_.steps = sim.step;
}

template <int D>
void Run<D>::end_stage(int k, bool stopped, bool reached_static) {
  const Simulation<D>& sim = *sim_;
  const Stage<D>& stage = sim.stages[size_t(k)];
  const std::string status = !end_.failure.empty() ? "unstable"
                             : end_.interrupted    ? "interrupted"
                             : stopped             ? "stopped"
                             : reached_static      ? "static"
                             : stage.until_static  ? "not_static"
                                                   : "done";
  stage_records_.push_back(stage_record(status));
  if (status != "not_static") return;
  // Still too fast, or slow enough only for part of the window at the end.
  const std::string why =
      sim.motion_speed > stage.static_speed
          ? fmt::format("particles still moving at up to {:.3g} m/s > static_speed = {:.3g} m/s",
                        sim.motion_speed, stage.static_speed)
          : fmt::format(
                "particles slower than static_speed = {:.3g} m/s only since t = {:.4g} s, less "
                "than static_window = {:.3g} s",
                stage.static_speed, ls_.static_since, ls_.static_window);
  if (sim.ranks->root())
    spdlog::warn("stage {} '{}' did not reach static within max_time = {} s ({}){}", k + 1,
                 stage.name, stage.duration, why,
                 stage.stop_if_not_static ? ": the run stops here (if_not_static: stop)" : "");
  if (stage.stop_if_not_static && k + 1 < int(sim.stages.size()))
    end_.stopped_by_stage = stage.name;
}

template <int D>
nlohmann::json Run<D>::run_strength_reduction() {
  Simulation<D>& sim = *sim_;
  if (!cfg_.params.given("strength_reduction")) return nullptr;
  const bool ready = end_.failure.empty() && !end_.interrupted && end_.write_error.empty() &&
                     !end_.budget && !stage_records_.empty() &&
                     stage_records_.size() == sim.stages.size() &&
                     stage_records_.back()["status"] == "static";
  if (!ready)
    return {{"status", "not_run"},
            {"reason", "the stages did not end in a static state (see stages[])"}};
  nlohmann::json srf = strength_reduction();
  if (opt_.write_output && srf_mechanism_.step >= 0)  // the lowest failed F's mechanism
    guarded([&] {
      std::swap(sim.last_good, srf_mechanism_);
      sim.swap_last_good();
      write_frame("strength_reduction");
      sim.swap_last_good();
      std::swap(sim.last_good, srf_mechanism_);
    });
  if (srf["status"] == "interrupted") {
    end_.interrupted = InterruptGuard::requested();
    if (sim.ranks->distributed()) end_.interrupted = sim.ranks->max(end_.interrupted);
  }
  return srf;
}

template <int D>
void Run<D>::write_interrupted_state(const nlohmann::json& srf) {
  // The state after the last complete step, as a regular frame, and a checkpoint to resume
  // from, also without output.checkpoint (the resumed run removes it when it ends).
  Simulation<D>& sim = *sim_;
  if (!end_.interrupted || !opt_.write_output) return;
  guarded([&] {
    if (ls_.frame_step != sim.step) write_frame("");
    sample_probes(true);
    if (ls_.history_step != sim.step) write_history();
    // Resumable from inside a stage (checkpoint_image), not from inside the strength
    // reduction: its search would start again from a stage ended.
    const bool in_search = srf.is_object() && srf.value("status", "") == "interrupted";
    if (checkpoint_problem().empty() && !in_search) {
      write_checkpoint(checkpoint_image());
      end_.resumable = true;
    }
  });
}

template <int D>
nlohmann::json Run<D>::run_summary(double wall, double wall_max, double particles) {
  Simulation<D>& sim = *sim_;
  const bool distributed = sim.ranks->distributed();
  nlohmann::json s = base_summary();
  s["status"] = !end_.failure.empty() ? "unstable" : end_.interrupted ? "interrupted" : "ok";
  if (end_.interrupted) s["interrupted_by"] = signal_name(end_.interrupted);
  s["steps"] = sim.step;
  s["end_time"] = sim.time;
  s["wall_seconds"] = wall;
  s["threads"] = sim.threads;
  s["particle_steps_per_second"] =
      wall_max > 0 ? particles * double(sim.step + srf_steps_) / wall_max : 0.0;
  if (distributed) s["ranks"] = sim.ranks->size();
  s["dt_min"] = ls_.dt_min < 1e300 ? ls_.dt_min : 0.0;
  s["dt_max"] = ls_.dt_max;
  s["frames"] = frames_;
  if (sim.profiling) s["profile_seconds"] = sim.profile;
  if (sim.profiling && distributed) profile_by_rank(s);
  const Energies e1 = sim.energies();
  summarise_masses(s);
  s["energy_initial"] = energy_json(ls_.e0);
  s["energy_final"] = energy_json(e1);
  if (sim.ledger.enabled)
    s["energy_balance"] = balance_json(energy_balance(e1, ls_.e0, sim.ledger.global(*sim.ranks)));
  s["verify"] = verify_summary();  // always there: empty without a reference
  if (!cfg_.params.list("stages").empty()) {
    nlohmann::json records = stage_records_;
    for (size_t k = records.size(); k < sim.stages.size(); ++k)
      records.push_back({{"name", sim.stages[k].name}, {"status", "not_run"}});
    s["stages"] = records;
    if (!end_.stopped_by_stage.empty()) s["stopped_after_stage"] = end_.stopped_by_stage;
  }
  return s;
}

template <int D>
void Run<D>::summarise_masses(nlohmann::json& s) const {
  // Sources and sinks: counts and the mass balance (round-off when nothing is lost). Over the
  // ranks: masses now and initial, particles and mass created and removed.
  const Simulation<D>& sim = *sim_;
  double sums[6] = {sim.total_mass(),    sim.initial_mass, double(sim.created),
                    double(sim.removed), sim.mass_created, sim.mass_removed};
  sim.ranks->sum(sums, 6);
  const double mass_now = sums[0], mass_initial = sums[1], mass_created = sums[4],
               mass_removed = sums[5];
  s["particles_created"] = size_t(sums[2]);
  s["particles_removed"] = size_t(sums[3]);
  s["mass"] = {{"initial", mass_initial},
               {"final", mass_now},
               {"created", mass_created},
               {"removed", mass_removed},
               {"balance", mass_now + mass_removed - mass_created - mass_initial}};
}

template <int D>
nlohmann::json Run<D>::verify_summary() {
  Simulation<D>& sim = *sim_;
  if (!sim.reference) return nlohmann::json::object();
  nlohmann::json v = nlohmann::json::object();
  const std::map<std::string, double> metrics = sim.reference->metrics(sim);
  for (const auto& [k, x] : metrics) v[k] = x;
  v["reference"] = cfg_.params.section("verify").type();
  for (const Comparison& c : sim.reference->comparisons(metrics))
    if (metrics.count(c.measured) && metrics.count(c.reference))
      v["comparisons"].push_back({{"measured", c.measured},
                                  {"value", metrics.at(c.measured)},
                                  {"reference", c.reference},
                                  {"reference_value", metrics.at(c.reference)},
                                  {"source", c.source}});
  const auto series = sim.reference->series();
  for (const auto& [name, values] : series) v["series"][name] = values;
  if (opt_.write_output && !series.empty() && sim.ranks->root())  // the series: all ranks'
    guarded([&] { write_series_csv(dir_ / "verify.csv", series); });
  return v;
}

template <int D>
void Run<D>::record_failure(RunResult& res) {
  Simulation<D>& sim = *sim_;
  res.exit_code = 3;
  std::string written;
  if (opt_.write_output) {
    // The last state that passed the check as the last regular frame (unless it is one
    // already), then the state at detection as 'failed'. With checkpoints also as a
    // checkpoint (unless the newest is of that step already).
    const auto& good = sim.last_good;
    if (good.step >= 0) {
      const bool frame = good.step != ls_.frame_step;
      const bool checkpoint =
          keep_good_image_ && good_image_.step == good.step &&
          (checkpoints_.empty() || checkpoint_step(checkpoints_.back()) < good.step);
      if (frame || checkpoint) {
        sim.swap_last_good();
        guarded([&] {
          if (frame) write_frame("");
          if (checkpoint) write_checkpoint(good_image_);
        });
        sim.swap_last_good();
      }
      res.summary["last_good"] = {{"step", good.step}, {"time", good.time}};
      written = "; the last state that passed the check (step " + std::to_string(good.step) +
                ", t = " + format_number(good.time) + " s) is the last regular frame";
      if (keep_good_image_ && !checkpoints_.empty() &&
          checkpoint_step(checkpoints_.back()) == good.step) {
        res.summary["last_good"]["checkpoint"] = checkpoints_.back().filename().string();
        written += " and " + checkpoints_.back().filename().string();
      }
    }
    guarded([&] { write_frame("failed"); });
    written += "; the state at detection was written as the frame labelled 'failed'";
  }
  res.message = "loam: error: unstable run at step " + std::to_string(sim.step) +
                ", t = " + format_number(sim.time) + " s: " + end_.failure + written + "\n";
  res.summary["failure"] = res.message;
}

template <int D>
void Run<D>::record_interruption(RunResult& res) const {
  const Simulation<D>& sim = *sim_;
  res.exit_code = 128 + end_.interrupted;
  res.message =
      "loam: interrupted by " + signal_name(end_.interrupted) + " at step " +
      std::to_string(sim.step) + ", t = " + format_number(sim.time) + " s" +
      (opt_.write_output ? ": the last complete step was written as the last frame, with the "
                           "history, probes and summary.json (status: interrupted)"
                         : "") +
      (end_.resumable ? "; go on with: loam run CONFIG --resume " + dir_.string() : "") + "\n";
}

template <int D>
void Run<D>::close_outputs(RunResult& res) {
  Simulation<D>& sim = *sim_;
  guarded([&] {
    if (!end_.failure.empty()) write_history();
    history_.close();
    for (auto& pr : probes_) pr.csv.close();
    writer_->close();
  });
  // Every rank reports the same write failure (a rank's file may have failed alone).
  if (sim.ranks->distributed()) end_.write_error = sim.ranks->first_message(end_.write_error);
  if (!end_.write_error.empty()) {
    // Keep what was written: the history and probe rows so far are renamed to their names.
    history_.close(false);
    for (auto& pr : probes_) pr.csv.close(false);
    res.exit_code = 4;
    res.message = "loam: error: " + end_.write_error + "; the run stopped at step " +
                  std::to_string(sim.step) + ", t = " + format_number(sim.time) +
                  " s (the frames, history and probes written before are intact)\n";
    res.summary["status"] = "write_failed";
    res.summary["write_error"] = end_.write_error;
  }
  if (!sim.ranks->root()) return;  // summary.json is the first rank's
  if (end_.write_error.empty()) {
    guarded([&] { write_summary(res.summary); });
    if (!end_.write_error.empty()) {  // only summary.json failed
      res.exit_code = 4;
      res.message += "loam: error: " + end_.write_error + "\n";
    }
  } else {
    try {  // the summary with status write_failed, if the disk still takes it
      write_summary(res.summary);
    } catch (const std::exception&) {
    }
  }
}

template <int D>
void Run<D>::drop_resume_checkpoints(const RunResult& res) {
  // A run that was not asked for checkpoints keeps none once it has ended: the one its
  // interruption left was only for --resume.
  bool ended = opt_.write_output && res.exit_code == 0;
  if (sim_->ranks->distributed())
    ended = sim_->ranks->max(int(!ended)) == 0;  // only the first rank writes summary.json
  if (!ended || checkpointing()) return;
  for (const auto& file : checkpoints_) {
    std::error_code ec;
    fs::remove(file, ec);
  }
}

/// The run: its stages step by step with the outputs due, the strength reduction after them,
/// then summary.json and the terminal's report.
template <int D>
RunResult Run<D>::loop() {
  InterruptGuard guard;  // SIGINT, SIGTERM: stop after the current step; SIGXFSZ ignored
  start_loop();
  run_stages();
  const nlohmann::json srf = run_strength_reduction();
  write_interrupted_state(srf);
  const double wall = std::chrono::duration<double>(Clock::now() - progress_.start).count();
  // The slowest rank's wall time gives the run's particle-steps per second.
  const double wall_max = sim_->ranks->distributed() ? sim_->ranks->max(wall) : wall;
  const double particles = global_particles();
  RunResult res;
  res.summary = run_summary(wall, wall_max, particles);
  if (!srf.is_null()) {
    res.summary["strength_reduction"] = srf;
    for (const char* k : {"factor_of_safety", "factor_of_safety_bracket"})
      if (srf.contains(k)) res.summary[k] = srf[k];
  }
  if (!end_.failure.empty()) record_failure(res);
  if (end_.interrupted && end_.failure.empty()) record_interruption(res);
  if (opt_.write_output) close_outputs(res);
  drop_resume_checkpoints(res);
  if (opt_.report && end_.failure.empty() && !end_.interrupted && sim_->ranks->root())
    report_end(res.summary, opt_.write_output ? dir_.string() : std::string(), particles, wall_max);
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
    if (opt.report) fputs(diag.format().c_str(), stderr);
    return 2;
  }
  RunResult r = run_config(cfg, opt);
  if (!r.message.empty() && opt.report) fputs(r.message.c_str(), stderr);
  return r.exit_code;
}

}  // namespace loam
