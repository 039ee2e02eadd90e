// Checkpoints of a run (output.checkpoint, --resume, the interrupt checkpoint): what Run<D> writes
// and restores; the file format is checkpoint.hpp's.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "checkpoint.hpp"
#include "run.hpp"
#include "simulation.hpp"

namespace loam {

namespace {

/// A checkpoint's name: checkpoint_<step, 8 digits><tag>.h5, the tag naming the rank's own file
/// under mpirun (Ranks::file_tag, "" serially).
std::string checkpoint_name(long step, const std::string& tag) {
  char name[64];
  std::snprintf(name, sizeof name, "checkpoint_%08ld", step);
  return name + tag + ".h5";
}

/// The checkpoints of an output directory with this tag (a rank's own under mpirun), oldest
/// first (the zero-padded step sorts by name).
std::vector<std::filesystem::path> checkpoint_files(const std::filesystem::path& dir,
                                                    const std::string& tag) {
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    if (detail::checkpoint_step(e.path(), tag) >= 0) files.push_back(e.path());
  std::sort(files.begin(), files.end());
  return files;
}

}  // namespace

namespace detail {

/// The step in a checkpoint's name, or -1 if the name is not a checkpoint's with this tag.
long checkpoint_step(const std::filesystem::path& file, const std::string& tag) {
  const std::string n = file.filename().string();
  constexpr size_t kDigits = 8, kPrefix = 11;  // "checkpoint_"
  if (n.size() != kPrefix + kDigits + tag.size() + 3 || n.rfind("checkpoint_", 0) != 0 ||
      n.compare(kPrefix + kDigits, std::string::npos, tag + ".h5") != 0)
    return -1;
  for (size_t k = kPrefix; k < kPrefix + kDigits; ++k)
    if (n[k] < '0' || n[k] > '9') return -1;
  return std::stol(n.substr(kPrefix, kDigits));
}

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

// The members defined here, for the dimensions runner.cpp runs.
#define LOAM_RUN_CHECKPOINT_MEMBERS(D)                                      \
  template std::string Run<D>::checkpoint_problem() const;                  \
  template typename Run<D>::CheckpointImage Run<D>::checkpoint_image();     \
  template fs::path Run<D>::write_checkpoint(const CheckpointImage& image); \
  template void Run<D>::restore_checkpoint();                               \
  template std::string Run<D>::find_resume_checkpoint();                    \
  template std::string Run<D>::resume_layout_hint(const fs::path& dir) const;
LOAM_RUN_CHECKPOINT_MEMBERS(1)
LOAM_RUN_CHECKPOINT_MEMBERS(2)
LOAM_RUN_CHECKPOINT_MEMBERS(3)
#undef LOAM_RUN_CHECKPOINT_MEMBERS

}  // namespace detail
}  // namespace loam
