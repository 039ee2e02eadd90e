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

/// A checkpoint's name: checkpoint_<step, 8 digits><tag>.h5, the tag naming the rank's own file
/// under mpirun (Ranks::file_tag, "" serially).
std::string checkpoint_name(long step, const std::string& tag) {
  char name[64];
  std::snprintf(name, sizeof name, "checkpoint_%08ld", step);
  return name + tag + ".h5";
}

/// The step in a checkpoint's name, or -1 if the name is not a checkpoint's with this tag.
long checkpoint_step(const std::filesystem::path& file, const std::string& tag = "") {
  const std::string n = file.filename().string();
  constexpr size_t kDigits = 8, kPrefix = 11;  // "checkpoint_"
  if (n.size() != kPrefix + kDigits + tag.size() + 3 || n.rfind("checkpoint_", 0) != 0 ||
      n.compare(kPrefix + kDigits, std::string::npos, tag + ".h5") != 0)
    return -1;
  for (size_t k = kPrefix; k < kPrefix + kDigits; ++k)
    if (n[k] < '0' || n[k] > '9') return -1;
  return std::stol(n.substr(kPrefix, kDigits));
}

/// The checkpoints of an output directory with this tag (a rank's own under mpirun), oldest
/// first (the zero-padded step sorts by name).
std::vector<std::filesystem::path> checkpoint_files(const std::filesystem::path& dir,
                                                    const std::string& tag) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (checkpoint_step(e.path(), tag) >= 0) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

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
// A checkpoint holds what the loop needs to go on bit for bit: every particle field of every set
// in its current order, the ids, bodies and materials, each set's partition (the block order of
// the scatter; it depends on the thread count, so a resume with other threads sorts again and is
// then not bitwise), the simulation's counters, the loop's state (LoopState), the writer's frame
// list and the state of the reference and the sources (Reference::save_state). The config echo,
// the version and the commit must match the resumed run's.

/// Why output.checkpoint cannot be used with this run ("" if it can).
template <int D>
std::string Run<D>::checkpoint_problem() const {
  std::vector<double> state;
  if (sim_->reference && !sim_->reference->save_state(state))
    return "the reference '" + cfg_.params.section("verify").type() +
           "' cannot be checkpointed yet (its state is not saved)";
  for (size_t i = 0; i < sim_->sources.size(); ++i)
    if (!sim_->sources[i]->save_state(state))
      return "source " + std::to_string(i) + " cannot be checkpointed yet (its state is not saved)";
  return "";
}

/// The run's scalars a checkpoint holds besides the particles, each with where it lives: the
/// one list write and restore go through. f(name, value&) for every one.
template <int D>
template <class F>
void Run<D>::for_each_checkpoint_scalar(F&& f) {
  Simulation<D>& sim = *sim_;
  f("sim.time", sim.time);
  f("sim.step", sim.step);
  f("sim.dt", sim.dt);
  f("sim.max_speed", sim.max_speed);
  f("sim.created", sim.created);
  f("sim.removed", sim.removed);
  f("sim.mass_created", sim.mass_created);
  f("sim.mass_removed", sim.mass_removed);
  f("sim.initial_mass", sim.initial_mass);
  f("sim.next_id", sim.next_particle_id());
  f("run.frames", frames_);
  f("run.next_frame_time", ls_.next_frame_time);
  f("run.dt_first", ls_.dt_first);
  f("run.dt_min", ls_.dt_min);
  f("run.dt_max", ls_.dt_max);
  f("run.frame_step", ls_.frame_step);
  f("run.history_step", ls_.history_step);
  f("run.e0.kinetic", ls_.e0.kinetic);
  f("run.e0.strain", ls_.e0.strain);
  f("run.e0.gravity", ls_.e0.gravity);
  f("run.stage", ls_.stage);
  f("run.stage_step0", ls_.stage_step0);
  f("run.stage_start", ls_.stage_start);
  f("run.static_since", ls_.static_since);
  f("run.static_window", ls_.static_window);
  f("sim.stage", sim.stage);
  f("sim.loads_start", sim.loads_start);
}

template <int D>
typename Run<D>::CheckpointImage Run<D>::checkpoint_image() {
  CheckpointImage image;
  image.step = sim_->step;
  for_each_checkpoint_scalar(
      [&](const char* name, auto& v) { image.scalars.emplace_back(name, double(v)); });
  image.momentum = ls_.e0.momentum;
  image.writer = writer_->state();
  // A stage the run was interrupted in has a record, "interrupted", that a resumed run replaces
  // with the stage's own: the image holds the stages ended before it, as one taken mid-stage.
  nlohmann::json stages = stage_records_;
  if (!stages.empty() && stages.back()["status"] == "interrupted") stages.erase(stages.size() - 1);
  image.stages = stages.dump();
  const Simulation<D>& sim = *sim_;
  std::vector<double> state;
  if (sim.reference && sim.reference->save_state(state))
    image.plugins.emplace_back("plugin.reference", state);
  for (size_t i = 0; i < sim.sources.size(); ++i)
    if (state.clear(), sim.sources[i]->save_state(state))
      image.plugins.emplace_back("plugin.source." + std::to_string(i), state);
  for (size_t i = 0; i < sim.boundaries.size(); ++i)
    if (state.clear(), sim.boundaries[i]->save_state(state))
      image.plugins.emplace_back("plugin.boundary." + std::to_string(i), state);
  if (!sim.reactions.empty()) image.plugins.emplace_back("sim.reactions", sim.reactions.state());
  if (!sim.rigid_records.empty())
    image.plugins.emplace_back("sim.rigid_records", sim.rigid_records.state());
  if (sim.ledger.enabled) image.plugins.emplace_back("sim.energy_ledger", sim.ledger.state());
  return image;
}

template <int D>
fs::path Run<D>::write_checkpoint(const CheckpointImage& image) {
  const Simulation<D>& sim = *sim_;
  const fs::path file = dir_ / checkpoint_name(image.step, sim.ranks->file_tag());
  CheckpointWriter w(file.string());
  w.text("meta.format", "loam checkpoint 1");
  w.text("meta.version", loam_version() + " " + git_commit());
  w.text("meta.config", cfg_.params.to_json().dump());
  w.scalar("meta.ranks", double(sim.ranks->size()));
  for (const auto& [k, v] : image.scalars) w.scalar(k, v);
  w.doubles("run.e0.momentum", image.momentum);
  for (size_t k = 0; k < sim.sets.size(); ++k) {
    const ParticleSet<D>& set = sim.sets[k];
    const Particles<D>& P = set.particles;
    const std::string pre = "set." + std::to_string(k) + ".";
    w.scalar(pre + "size", double(P.size()));
    w.u32(pre + "id", P.id);
    w.u16(pre + "material", P.material);
    w.u16(pre + "body", P.body);
    nlohmann::json fields = nlohmann::json::array();  // name, components (to re-request)
    for (int f = 0; f < P.num_fields(); ++f)
      if (P.has(f)) {
        fields.push_back({P.info(f).name, P.info(f).components});
        for (int c = 0; c < P.info(f).components; ++c)
          w.doubles(pre + "field." + P.info(f).name + "." + std::to_string(c), P.col(f, c),
                    P.size());
      }
    w.text(pre + "fields", fields.dump());
    w.scalar(pre + "last_sort", double(set.last_sort));
    w.scalar(pre + "resized", set.resized ? 1.0 : 0.0);
    // The partition: threads, the material ranges, then per slab its rows and ranges.
    std::vector<double> part{double(set.partition.threads),
                             double(set.partition.material_ranges.size())};
    for (const auto& r : set.partition.material_ranges)
      part.insert(part.end(), {double(r.begin), double(r.end)});
    part.push_back(double(set.partition.slabs.size()));
    for (const auto& slab : set.partition.slabs) {
      part.insert(part.end(),
                  {double(slab.row_min), double(slab.row_max), double(slab.ranges.size())});
      for (const auto& r : slab.ranges) part.insert(part.end(), {double(r.begin), double(r.end)});
    }
    w.doubles(pre + "partition", part);
  }
  w.text("run.writer", image.writer);
  w.text("run.stages", image.stages);
  for (const auto& [k, v] : image.plugins) w.doubles(k, v);
  w.close();
  checkpoints_.push_back(file);
  while (int(checkpoints_.size()) > checkpoint_keep_) {
    std::error_code ec;
    fs::remove(checkpoints_.front(), ec);
    checkpoints_.erase(checkpoints_.begin());
  }
  return file;
}

template <int D>
void Run<D>::restore_checkpoint() {
  Simulation<D>& sim = *sim_;
  CheckpointReader r(resume_file_.string());
  for_each_checkpoint_scalar(
      [&](const char* name, auto& v) { v = std::remove_reference_t<decltype(v)>(r.scalar(name)); });
  ls_.e0.momentum = r.doubles("run.e0.momentum");
  for (size_t k = 0; k < sim.sets.size(); ++k) {
    ParticleSet<D>& set = sim.sets[k];
    Particles<D>& P = set.particles;
    const std::string pre = "set." + std::to_string(k) + ".";
    // A field a plugin requested after the set-up (during a step) exists in the checkpoint but
    // not yet here: request it with its stored size, then fill every field.
    for (const auto& f : nlohmann::json::parse(r.text(pre + "fields"))) {
      const std::string fname = f[0];
      const int h = P.find(fname);
      if (h < 0 || !P.has(h)) {
        FieldInfo info;
        info.name = fname;
        info.components = f[1];
        P.request(info);
      }
    }
    P.resize(size_t(r.scalar(pre + "size")));
    P.id = r.u32(pre + "id");
    P.material = r.u16(pre + "material");
    P.body = r.u16(pre + "body");
    for (int f = 0; f < P.num_fields(); ++f)
      if (P.has(f))
        for (int c = 0; c < P.info(f).components; ++c) {
          const auto v = r.doubles(pre + "field." + P.info(f).name + "." + std::to_string(c));
          std::copy(v.begin(), v.end(), P.col(f, c));
        }
    set.last_sort = long(r.scalar(pre + "last_sort"));
    set.resized = r.scalar(pre + "resized") != 0;
    // The slabs do not depend on the thread count (framework/partition.hpp): a run resumed on
    // another number of threads keeps its block order and its bits.
    const auto part = r.doubles(pre + "partition");
    size_t i = 1;
    auto next = [&] { return size_t(part.at(i++)); };
    set.partition.threads = sim.threads;
    set.partition.material_ranges.assign(next(), {});
    for (auto& m : set.partition.material_ranges) m.begin = next(), m.end = next();
    set.partition.slabs.assign(next(), {});
    for (auto& slab : set.partition.slabs) {
      slab.row_min = int(next());
      slab.row_max = int(next());
      slab.ranges.assign(next(), {});
      for (auto& range : slab.ranges) range.begin = next(), range.end = next();
    }
  }
  if (sim.reference) sim.reference->restore_state(r.doubles("plugin.reference"));
  for (size_t i = 0; i < sim.sources.size(); ++i)
    sim.sources[i]->restore_state(r.doubles("plugin.source." + std::to_string(i)));
  // The writer's frame list comes back once the writer is open (loop()).
  resume_writer_state_ = r.text("run.writer");
  stage_records_ = nlohmann::json::parse(r.text("run.stages"));
  // The plugins of the stages begun so far (their particle changes are in the checkpoint).
  for (int k = 0; k <= sim.stage; ++k) sim.swap_stage_plugins(k);
  // The current stage's conditions with a measured state (the config and the stage decide which,
  // so the checkpoint has an array for each that saves one).
  std::vector<double> probe;
  for (size_t i = 0; i < sim.boundaries.size(); ++i)
    if (probe.clear(), sim.boundaries[i]->save_state(probe))
      sim.boundaries[i]->restore_state(r.doubles("plugin.boundary." + std::to_string(i)));
  if (!sim.reactions.empty()) sim.reactions.restore(r.doubles("sim.reactions"));
  if (!sim.rigid_records.empty()) sim.rigid_records.restore(r.doubles("sim.rigid_records"));
  if (sim.ledger.enabled) sim.ledger.restore(r.doubles("sim.energy_ledger"));
  // The checkpoints of the run so far, and none from beyond this one (that future is redone).
  for (const auto& file : checkpoint_files(dir_, sim.ranks->file_tag())) {
    if (checkpoint_step(file, sim.ranks->file_tag()) > sim.step) {
      std::error_code ec;
      fs::remove(file, ec);
    } else {
      checkpoints_.push_back(file);
    }
  }
}

/// --resume DIR (its newest readable checkpoint) or --resume FILE: sets dir_ and
/// resume_file_, and checks that the checkpoint is this run's (config, version, commit, rank
/// count). Under mpirun every rank reads its own file of one step: the newest step whose files
/// every rank can read (a FILE names the step; each rank takes its own file of it).
template <int D>
std::string Run<D>::find_resume_checkpoint() {
  const Ranks<D>& ranks = *sim_->ranks;
  const std::string tag = ranks.file_tag();
  const fs::path given(opt_.resume);
  std::vector<fs::path> candidates;
  std::string error;  // a checkpoint of another run: no older one is tried
  if (fs::is_directory(given)) {
    dir_ = given;
    candidates = checkpoint_files(given, tag);
    std::reverse(candidates.begin(), candidates.end());  // newest first
    if (candidates.empty())
      error = "no " + checkpoint_name(0, tag).replace(11, 8, "*") + " in " + given.string() +
              resume_layout_hint(given);
  } else if (fs::exists(given)) {
    dir_ = given.parent_path().empty() ? fs::path(".") : given.parent_path();
    if (!ranks.distributed()) {
      candidates.push_back(given);
    } else {  // the same step's file of this rank
      const std::string n = given.filename().string();
      const long step = n.size() > 9 ? checkpoint_step(given, n.substr(n.size() - 9, 6)) : -1;
      if (step < 0 || n.compare(n.size() - 9, 2, "_r") != 0)
        error = "--resume " + given.string() +
                ": under mpirun, give the output directory or a rank's checkpoint_<step>_rRRRR.h5";
      else
        candidates.push_back(dir_ / checkpoint_name(step, tag));
    }
  } else {
    error = "--resume " + given.string() + ": no such directory or checkpoint file";
  }
  std::string why;
  std::vector<double> readable;  // steps, newest first
  for (const auto& c : candidates) {
    if (!error.empty()) break;
    try {
      CheckpointReader r(c.string());
      if (r.text("meta.format") != "loam checkpoint 1") {
        why = c.string() + " is not a loam checkpoint";
        continue;
      }
      if (r.text("meta.version") != loam_version() + " " + git_commit()) {
        error = "checkpoint " + c.string() + " was written by loam " + r.text("meta.version") +
                ", this is " + loam_version() + " " + git_commit() + ": resume with that binary";
      } else if (r.text("meta.config") != cfg_.params.to_json().dump()) {
        error = "checkpoint " + c.string() + " belongs to another configuration (its config " +
                "echo differs from this run's after overrides): resume with the same file and " +
                "--set";
      } else if (const int n = r.has("meta.ranks") ? int(r.scalar("meta.ranks")) : 1;
                 n != ranks.size()) {
        error = "checkpoint " + c.string() + " was written by a run on " + std::to_string(n) +
                " rank(s), this one has " + std::to_string(ranks.size()) +
                ": resume at the same rank count";
      } else {
        readable.push_back(double(std::max(0L, checkpoint_step(c, tag))));  // a FILE: any name
        if (!ranks.distributed()) break;  // the newest readable one
      }
    } catch (const std::exception& e) {
      why = e.what();  // an unreadable (e.g. cut) checkpoint: try the one before
    }
  }
  if (ranks.distributed()) error = ranks.first_message(error);
  if (!error.empty()) return error;
  // The newest step every rank can read (each rank's list, its length first).
  std::vector<double> mine{double(readable.size())};
  mine.insert(mine.end(), readable.begin(), readable.end());
  const std::vector<double> all = ranks.all_gather(mine);
  std::map<long, int> readers;
  int lists = 0;
  for (size_t i = 0; i < all.size(); ++lists)
    for (size_t n = size_t(all[i++]); n > 0; --n) ++readers[long(all[i++])];
  long step = -1;
  for (const auto& [s, count] : readers)
    if (count == lists) step = std::max(step, s);
  if (step < 0) {
    if (ranks.distributed() && why.empty()) why = "no step has a readable file on every rank";
    return "no valid checkpoint to resume from: " + ranks.first_message(why);
  }
  resume_file_ = candidates.size() == 1 ? candidates[0] : dir_ / checkpoint_name(step, tag);
  return "";
}

/// Why a directory has no checkpoint for this run's ranks: its checkpoints were written by a run
/// on another rank count (" ..." or "").
template <int D>
std::string Run<D>::resume_layout_hint(const fs::path& dir) const {
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string n = e.path().filename().string();
    if (n.rfind("checkpoint_", 0) != 0 || e.path().extension() != ".h5") continue;
    try {
      CheckpointReader r(e.path().string());
      const int ranks = r.has("meta.ranks") ? int(r.scalar("meta.ranks")) : 1;
      return " (its checkpoints were written by a run on " + std::to_string(ranks) +
             " rank(s): resume at that rank count)";
    } catch (const std::exception&) {
      continue;
    }
  }
  return " (a run writes one when it is interrupted by Ctrl-C or SIGTERM, and with "
         "output.checkpoint every_steps or every_wall_seconds)";
}

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
RunResult Run<D>::loop() {
  RunResult res;
  InterruptGuard guard;  // SIGINT, SIGTERM: stop after the current step; SIGXFSZ ignored
  Simulation<D>& sim = *sim_;
  const Params& out = cfg_.params.section("output");
  const long history_every = long(out.integer("history_every"));
  const bool resuming = !resume_file_.empty();
  const bool files = opt_.write_output;
  // A file that cannot be written (WriteError, a failed rename) stops the run with exit 4.
  // Serially the outputs after a failed one are skipped; under mpirun every rank still makes
  // every output's collective calls (a frame's gather, the history's energies, the probes'
  // gather), so that no rank waits for one that gave up; the ranks agree on the error after.
  std::string write_error;
  const bool distributed = sim.ranks->distributed();
  auto guarded = [&](auto&& write) {
    if (!write_error.empty() && !distributed) return;
    try {
      write();
    } catch (const WriteError& e) {
      if (write_error.empty()) write_error = e.what();
    } catch (const fs::filesystem_error& e) {
      if (write_error.empty())
        write_error = "cannot write " + e.path1().string() + ": " + e.code().message();
    }
  };
  if (resuming) {
    restore_checkpoint();
  } else {
    ls_.e0 = sim.energies();
  }
  long every_steps = 0;
  double every_time = 0;
  frame_interval(int(ls_.stage), every_steps, every_time);
  if (!resuming) ls_.next_frame_time = every_time;
  if (files)
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
  auto last_checkpoint = Clock::now();
  std::string failure;
  auto t0 = Clock::now(), last_report = t0;
  long steps_at_report = 0;
  const double min_dt_ratio = cfg_.params.section("time").real("min_dt_ratio");
  int interrupted = 0;  // the signal that stopped the run (InterruptGuard)
  const bool keep_good_image = files && sim.keep_last_good && checkpointing();
  const int num_stages = int(sim.stages.size());
  bool budget = false;           // --max-steps reached
  std::string stopped_by_stage;  // a stage that did not reach static (if_not_static: stop)
  bool within_stage = resuming;  // resumed within stage ls_.stage: it has begun already
  for (int k = resuming ? int(ls_.stage) : 0; k < num_stages; ++k) {
    Stage<D>& stage = sim.stages[size_t(k)];
    if (!within_stage) {
      sim.begin_stage(k);
      ls_.stage = k;
      ls_.stage_start = sim.time;
      ls_.stage_step0 = sim.step;
      ls_.static_since = -1;
      ls_.static_window = stage.static_window > 0 ? stage.static_window : default_static_window();
      if (stage.sets_output) {
        frame_interval(k, every_steps, every_time);
        ls_.next_frame_time = sim.time + every_time;
      }
    }
    // The state at the stage's start (or the checkpoint) passed the checks. With checkpoints,
    // the run's own state is kept beside the particles' (good_image_), for a checkpoint of the
    // last good state.
    if (sim.keep_last_good) sim.save_last_good();
    if (keep_good_image) good_image_ = checkpoint_image();
    sim.track_motion = stage.until_static;
    const double t_end = ls_.stage_start + stage.duration;
    bool reached_static = false;
    while (write_error.empty() && sim.time < t_end * (1 - 1e-12) &&
           (opt_.max_steps < 0 || sim.step < opt_.max_steps)) {
      double dt = sim.stable_dt();
      if (ls_.dt_first == 0) ls_.dt_first = dt;
      if (dt < min_dt_ratio * ls_.dt_first) {
        failure = "the stable time step collapsed to " + format_number(dt) + " s, below " +
                  "time.min_dt_ratio = " + format_number(min_dt_ratio) + " of the first step's " +
                  format_number(ls_.dt_first) + " s (largest particle speed " +
                  format_number(sim.max_speed) +
                  " m/s): a wave or particle speed exploded; remedies: scheme.update: musl, a "
                  "smaller time.cfl, a smooth shape function (gimp, bspline2, cpdi)";
        break;
      }
      if (sim.time + dt > t_end) dt = t_end - sim.time;
      ls_.dt_min = std::min(ls_.dt_min, dt);
      ls_.dt_max = std::max(ls_.dt_max, dt);
      // Whether the step ends at a frame or the stage's end (the particles are then checked).
      const long next_step = sim.step + 1;
      const double next_time = sim.time + dt;
      const bool frame_due =
          files && ((every_steps && next_step % every_steps == 0) ||
                    (every_time > 0 && next_time >= ls_.next_frame_time * (1 - 1e-9)));
      const bool last_of_stage = next_time >= t_end * (1 - 1e-12);
      bool last = last_of_stage || next_step == opt_.max_steps;
      // A checkpoint is written only of a state that passed the check. Under mpirun every rank
      // writes its file of the same step: the wall-clock interval is up when it is on any rank.
      bool wall_due =
          checkpoint_wall_ > 0 &&
          std::chrono::duration<double>(Clock::now() - last_checkpoint).count() >= checkpoint_wall_;
      if (distributed && checkpoint_wall_ > 0) wall_due = sim.ranks->max(int(wall_due)) != 0;
      const bool checkpoint_due =
          files && !last &&
          ((checkpoint_every_ > 0 && next_step % checkpoint_every_ == 0) || wall_due);
      if (!sim.advance(dt, frame_due || last || checkpoint_due)) {
        failure = sim.failure;
        break;
      }
      if (sim.step >= sim.max_steps && sim.time < sim.end_time * (1 - 1e-12)) {
        failure = "time.max_steps = " + std::to_string(sim.max_steps) +
                  " reached before t = " + format_number(sim.end_time) +
                  " s; the time step fell to " + format_number(dt) + " s (it was " +
                  format_number(ls_.dt_max) + " s at most)";
        break;
      }
      // until: static, judged on checked steps (a frame ends the stage there).
      if (stage.until_static && sim.checked_step == sim.step) {
        reached_static = at_rest(sim.time, sim.motion_speed, stage.static_speed, ls_.static_window,
                                 ls_.static_since);
        last = last || reached_static;
      }
      if (sim.reference) sim.reference->sample(sim);
      if (files) {
        guarded([&] { sample_probes(last); });
        if (frame_due || last)
          guarded([&] {
            write_frame("");
            ls_.frame_step = sim.step;
            while (every_time > 0 && ls_.next_frame_time <= sim.time * (1 + 1e-9))
              ls_.next_frame_time += every_time;
          });
        if ((history_every > 0 && sim.step % history_every == 0) ||
            (history_every == 0 && (frame_due || last)))
          guarded([&] {
            write_history();
            ls_.history_step = sim.step;
          });
        if (checkpoint_due && !last)  // not of a stage's end (static is known after it)
          guarded([&] {
            write_checkpoint(checkpoint_image());
            last_checkpoint = Clock::now();
          });
        if (keep_good_image && sim.last_good.step == sim.step)
          guarded([&] { good_image_ = checkpoint_image(); });
      }
      if (distributed) write_error = sim.ranks->first_message(write_error);
      if (!write_error.empty()) break;
      auto now = Clock::now();
      if (!opt_.quiet && opt_.report &&
          std::chrono::duration<double>(now - last_report).count() > 3.0) {
        double el = std::chrono::duration<double>(now - t0).count();
        double sps = double(sim.step - steps_at_report) /
                     std::chrono::duration<double>(now - last_report).count();
        double frac = sim.time / sim.end_time;
        double eta = frac > 0 ? el * (1 - frac) / frac : 0;
        spdlog::info("{:5.1f}%  t = {:.4g} s  step {}  {:.3g} steps/s  ETA {:.0f} s", 100 * frac,
                     sim.time, sim.step, sps, eta);
        last_report = now;
        steps_at_report = sim.step;
      }
      interrupted = InterruptGuard::requested();
      if (distributed) interrupted = sim.ranks->max(interrupted);  // every rank stops together
      if (interrupted != 0) break;
      if (reached_static) break;
    }
    within_stage = false;
    budget = opt_.max_steps >= 0 && sim.step >= opt_.max_steps && sim.time < t_end * (1 - 1e-12);
    const bool stopped = !failure.empty() || interrupted || !write_error.empty() || budget;
    if (!stage.params.path().empty()) {
      const std::string status = !failure.empty()     ? "unstable"
                                 : interrupted        ? "interrupted"
                                 : stopped            ? "stopped"
                                 : reached_static     ? "static"
                                 : stage.until_static ? "not_static"
                                                      : "done";
      stage_records_.push_back(stage_record(status));
      if (status == "not_static") {
        // Still too fast, or slow enough only for part of the window at the end.
        const std::string why =
            sim.motion_speed > stage.static_speed
                ? fmt::format(
                      "particles still moving at up to {:.3g} m/s > static_speed = "
                      "{:.3g} m/s",
                      sim.motion_speed, stage.static_speed)
                : fmt::format(
                      "particles slower than static_speed = {:.3g} m/s only since t = "
                      "{:.4g} s, less than static_window = {:.3g} s",
                      stage.static_speed, ls_.static_since, ls_.static_window);
        if (sim.ranks->root())
          spdlog::warn(
              "stage {} '{}' did not reach static within max_time = {} s ({}){}", k + 1, stage.name,
              stage.duration, why,
              stage.stop_if_not_static ? ": the run stops here (if_not_static: stop)" : "");
      }
      if (status == "not_static" && stage.stop_if_not_static && k + 1 < num_stages)
        stopped_by_stage = stage.name;
    }
    if (stopped || !stopped_by_stage.empty()) break;
  }
  nlohmann::json srf;  // strength_reduction: from the last stage's static state
  if (cfg_.params.given("strength_reduction")) {
    const bool ready = failure.empty() && !interrupted && write_error.empty() && !budget &&
                       !stage_records_.empty() && int(stage_records_.size()) == num_stages &&
                       stage_records_.back()["status"] == "static";
    if (ready) {
      srf = strength_reduction();
      if (files && srf_mechanism_.step >= 0)  // the failure mechanism of the lowest failed F
        guarded([&] {
          std::swap(sim.last_good, srf_mechanism_);
          sim.swap_last_good();
          write_frame("strength_reduction");
          sim.swap_last_good();
          std::swap(sim.last_good, srf_mechanism_);
        });
      if (srf["status"] == "interrupted") {
        interrupted = InterruptGuard::requested();
        if (distributed) interrupted = sim.ranks->max(interrupted);
      }
    } else {
      srf = {{"status", "not_run"},
             {"reason", "the stages did not end in a static state (see stages[])"}};
    }
  }
  // The state after the last complete step, as a regular frame, and a checkpoint to resume
  // from, also without output.checkpoint (the resumed run removes it when it ends).
  bool resumable = false;
  if (interrupted && files)
    guarded([&] {
      if (ls_.frame_step != sim.step) write_frame("");
      sample_probes(true);
      if (ls_.history_step != sim.step) write_history();
      // Resumable from inside a stage (checkpoint_image), not from inside the strength
      // reduction: its search would start again from a stage ended.
      const bool in_search = srf.is_object() && srf.value("status", "") == "interrupted";
      if (checkpoint_problem().empty() && !in_search) {
        write_checkpoint(checkpoint_image());
        resumable = true;
      }
    });
  double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  res.summary = base_summary();
  res.summary["status"] = !failure.empty() ? "unstable" : interrupted ? "interrupted" : "ok";
  if (interrupted) res.summary["interrupted_by"] = signal_name(interrupted);
  res.summary["steps"] = sim.step;
  res.summary["end_time"] = sim.time;
  res.summary["wall_seconds"] = wall;
  res.summary["threads"] = sim.threads;
  const double particles = global_particles();
  if (distributed) wall = sim.ranks->max(wall);
  res.summary["particle_steps_per_second"] =
      wall > 0 ? particles * double(sim.step + srf_steps_) / wall : 0.0;
  if (distributed) res.summary["ranks"] = sim.ranks->size();
  res.summary["dt_min"] = ls_.dt_min < 1e300 ? ls_.dt_min : 0.0;
  res.summary["dt_max"] = ls_.dt_max;
  res.summary["frames"] = frames_;
  if (sim.profiling) res.summary["profile_seconds"] = sim.profile;
  if (sim.profiling && distributed) profile_by_rank(res.summary);
  Energies e1 = sim.energies();
  // Sources and sinks: counts and the mass balance (round-off when nothing is lost).
  // Over the ranks: masses now and initial, particles and mass created and removed.
  double sums[6] = {sim.total_mass(),    sim.initial_mass, double(sim.created),
                    double(sim.removed), sim.mass_created, sim.mass_removed};
  sim.ranks->sum(sums, 6);
  const double mass_now = sums[0], mass_initial = sums[1], mass_created = sums[4],
               mass_removed = sums[5];
  res.summary["particles_created"] = size_t(sums[2]);
  res.summary["particles_removed"] = size_t(sums[3]);
  res.summary["mass"] = {{"initial", mass_initial},
                         {"final", mass_now},
                         {"created", mass_created},
                         {"removed", mass_removed},
                         {"balance", mass_now + mass_removed - mass_created - mass_initial}};
  res.summary["energy_initial"] = energy_json(ls_.e0);
  res.summary["energy_final"] = energy_json(e1);
  if (sim.ledger.enabled)
    res.summary["energy_balance"] =
        balance_json(energy_balance(e1, ls_.e0, sim.ledger.global(*sim.ranks)));
  res.summary["verify"] = nlohmann::json::object();  // always there: empty without a reference
  if (sim.reference) {
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
    res.summary["verify"] = v;
    if (files && !series.empty() && sim.ranks->root())  // the series are over all ranks
      guarded([&] { write_series_csv(dir_ / "verify.csv", series); });
  }
  if (!cfg_.params.list("stages").empty()) {
    nlohmann::json records = stage_records_;
    for (size_t k = records.size(); k < sim.stages.size(); ++k)
      records.push_back({{"name", sim.stages[k].name}, {"status", "not_run"}});
    res.summary["stages"] = records;
    if (!stopped_by_stage.empty()) res.summary["stopped_after_stage"] = stopped_by_stage;
  }
  if (!srf.is_null()) {
    res.summary["strength_reduction"] = srf;
    for (const char* k : {"factor_of_safety", "factor_of_safety_bracket"})
      if (srf.contains(k)) res.summary[k] = srf[k];
  }
  if (!failure.empty()) {
    res.exit_code = 3;
    std::string written;
    if (files) {
      // The last state that passed the check as the last regular frame (unless it is one
      // already), then the state at detection as 'failed'.
      // With checkpoints also as a checkpoint (unless the newest is of that step already).
      const auto& good = sim.last_good;
      if (good.step >= 0) {
        const bool frame = good.step != ls_.frame_step;
        const bool checkpoint =
            keep_good_image && good_image_.step == good.step &&
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
        if (keep_good_image && !checkpoints_.empty() &&
            checkpoint_step(checkpoints_.back()) == good.step) {
          res.summary["last_good"]["checkpoint"] = checkpoints_.back().filename().string();
          written += " and " + checkpoints_.back().filename().string();
        }
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
                  (resumable ? "; go on with: loam run CONFIG --resume " + dir_.string() : "") +
                  "\n";
  }
  if (files) {
    guarded([&] {
      if (!failure.empty()) write_history();
      history_.close();
      for (auto& pr : probes_) pr.csv.close();
      writer_->close();
    });
    // Every rank reports the same write failure (a rank's file may have failed alone).
    if (distributed) write_error = sim.ranks->first_message(write_error);
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
    if (sim.ranks->root()) {  // summary.json is the first rank's
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
  }
  // A run that was not asked for checkpoints keeps none once it has ended: the one its
  // interruption left was only for --resume.
  bool ended = files && res.exit_code == 0;
  if (distributed) ended = sim.ranks->max(int(!ended)) == 0;  // only the first rank writes summary
  if (ended && !checkpointing())
    for (const auto& file : checkpoints_) {
      std::error_code ec;
      fs::remove(file, ec);
    }
  if (opt_.report && failure.empty() && !interrupted && sim.ranks->root())
    report_end(res.summary, files ? dir_.string() : std::string(), particles, wall);
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
