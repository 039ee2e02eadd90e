#pragma once
// Internal to the runner, included only by runner.cpp and run_output.cpp: one run of a validated
// configuration (Run<D>), its probes and the CSV files it writes. runner.cpp defines the loop and
// summary.json, run_output.cpp the output directory, the output checks, frames, probes and history.
#include <chrono>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "interrupt.hpp"
#include "runner.hpp"
#include "simulation.hpp"
#include "writer.hpp"

namespace loam {
namespace detail {

namespace fs = std::filesystem;

/// A CSV written under a temporary name and renamed when complete.
class CsvFile {
 public:
  void open(const fs::path& path, int digits = 12) {
    final_ = path;
    tmp_ = path;
    tmp_ += ".tmp";
    out_.open(tmp_);
    out_.precision(digits);
    register_temporary_file(tmp_.string());  // removed if a second signal stops the run
  }
  std::ofstream& out() { return out_; }
  /// Open for a resumed run: the rows of the existing file whose first column (the step) is at
  /// most max_step, with its header, are copied into the temporary file, which goes on.
  void open_resume(const fs::path& path, long max_step, int digits = 12) {
    std::vector<std::string> keep;
    {
      std::ifstream in(path);
      std::string line;
      if (std::getline(in, line)) keep.push_back(line);
      while (std::getline(in, line))
        if (!line.empty() && std::stol(line.substr(0, line.find(','))) <= max_step)
          keep.push_back(line);
    }
    open(path, digits);
    for (const auto& l : keep) out_ << l << "\n";
  }
  /// A failed write (the stream's state after a buffer flush) as WriteError naming the file.
  void check() {
    if (!out_) throw WriteError(final_.string(), WriteError::os_reason());
  }
  /// Flush, close and rename; with `report`, a failure is a WriteError (the file is renamed
  /// anyway: the rows written so far are kept).
  void close(bool report = true) {
    if (!out_.is_open()) return;
    errno = 0;
    out_.close();
    const bool failed = out_.fail();
    std::error_code ec;
    fs::rename(tmp_, final_, ec);
    unregister_temporary_file(tmp_.string());
    if (report && (failed || ec))
      throw WriteError(final_.string(), ec ? ec.message() : WriteError::os_reason());
  }

 private:
  fs::path final_, tmp_;
  std::ofstream out_;
};

/// until: static on a checked step at `time`: `since` is when the motion last fell to `limit` or
/// below (-1: it is above now); true once it has stayed there for `window`.
inline bool at_rest(double time, double speed, double limit, double window, double& since) {
  if (speed > limit)
    since = -1;
  else if (since < 0)
    since = time;
  return since >= 0 && time - since >= window * (1 - 1e-12);
}

template <int D>
struct Probe {
  std::string name;
  bool on_node = false;
  int set = 0;
  uint32_t particle_id = 0;
  size_t node = 0;           // its index among this rank's stored nodes, if it samples it
  bool samples_node = true;  // this rank owns the probe's node (every node serially)
  std::vector<std::string> fields;
  long every = 1;
  CsvFile csv;
};

/// The step in a checkpoint's file name checkpoint_<step, 8 digits><tag>.h5, or -1 when the
/// name is not a checkpoint's with this tag (run_checkpoint.cpp).
long checkpoint_step(const std::filesystem::path& file, const std::string& tag = "");

template <int D>
class Run {
 public:
  Run(const LoadedConfig& cfg, const RunOptions& opt) : cfg_(cfg), opt_(opt) {}

  RunResult execute(bool check_only);

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
  int strain_magnitude_ = -1, reset_F_ = -1;  // the strain_magnitude output and its reference
  long frames_ = 0;

  /// What the time loop carries from step to step besides the simulation (checkpointed).
  struct LoopState {
    double next_frame_time = 0, dt_first = 0, dt_min = 1e300, dt_max = 0;
    long frame_step = 0, history_step = 0;
    Energies e0;
    // The running stage: its index, where it began, and for until: static since when every
    // particle has been slower than static_speed (-1: not now) and the window it needs.
    long stage = 0, stage_step0 = 0;
    double stage_start = 0, static_since = -1, static_window = 0;
  };
  LoopState ls_;
  // Checkpoints (output.checkpoint, --resume; run_checkpoint.cpp).
  long checkpoint_every_ = 0;
  double checkpoint_wall_ = 0;
  int checkpoint_keep_ = 2;
  std::vector<fs::path> checkpoints_;  // oldest first
  fs::path resume_file_;               // --resume: the checkpoint to continue from
  std::string resume_writer_state_;    // its writer state, restored once the writer is open
  std::string checkpoint_problem() const;
  bool checkpointing() const { return checkpoint_every_ > 0 || checkpoint_wall_ > 0; }
  /// What a checkpoint holds besides the particles (the run's scalars, the writer's frame list,
  /// the plugins' state), taken when the particles passed the check: the image of the last
  /// good state is kept until a later step fails and is then written with its particles.
  struct CheckpointImage {
    long step = -1;
    std::vector<std::pair<std::string, double>> scalars;
    std::vector<double> momentum;
    std::string writer;
    std::string stages;  // the records of the stages completed (JSON)
    std::vector<std::pair<std::string, std::vector<double>>> plugins;
  };
  nlohmann::json stage_records_ = nlohmann::json::array();
  /// The record of the running stage as it ends ("static", "not_static", "done", ...).
  nlohmann::json stage_record(const std::string& status);
  /// The terminal's end of a finished run: the "done:" line and the run report
  /// (framework/run_report.hpp), or with --quiet the report's one line.
  void report_end(const nlohmann::json& summary, const std::string& out_dir, double particles,
                  double wall) const;
  /// The frame interval of stage k: the last stage up to k that sets one, or output:.
  void frame_interval(int k, long& every_steps, double& every_time) const;
  CheckpointImage good_image_;
  template <class F>
  void for_each_checkpoint_scalar(F&& f);
  CheckpointImage checkpoint_image();
  /// The checkpoint of `image` with the current particles; returns its file.
  fs::path write_checkpoint(const CheckpointImage& image);
  void restore_checkpoint();
  std::string find_resume_checkpoint();
  std::string resume_layout_hint(const fs::path& dir) const;

  // Output (run_output.cpp).
  void check_outputs(Diagnostics& diag);
  /// A node probe's node from `node` or `node_near`, checked; under mpirun its owner samples it.
  void locate_probe_node(const Params& pr, Probe<D>& probe, Diagnostics& diag) const;
  /// A particle probe's particle: of its set (bodies waiting for a stage included), the nearest
  /// to `particle_near` at t = 0 over all ranks; false (with the error) for a bad or empty set.
  bool locate_probe_particle(const Params& pr, Probe<D>& probe, Diagnostics& diag);
  std::string prepare_directory();
  /// The output directory: --out, or results/<config name>.
  fs::path output_directory() const;
  void refresh_derived();
  /// The strain_magnitude output of particle i (hencky_strain_norm since the last reset).
  double strain_magnitude(const Particles<D>& p, size_t i) const;
  void open_outputs(long resume_step = -1);
  void sample_probes(bool force);
  bool take_probe_sample(const Probe<D>& pr, std::vector<double>& values) const;
  void write_history();
  bool exchanges_particles() const { return !sim_->sources.empty() || !sim_->sinks.empty(); }
  void write_frame(const std::string& label);
  /// summary.json, written under a temporary name and renamed (WriteError on failure).
  void write_summary(const nlohmann::json& summary);

  /// The largest particle displacement from the displacement reference (initial_position).
  double largest_displacement() const;
  /// The static window when none is given: the time a P-wave takes to cross the grid's
  /// longest side.
  double default_static_window() const;

  // Strength reduction (strength_reduction.cpp).
  std::vector<int> srf_bodies_;                           // the bodies whose strength is reduced
  std::vector<std::unique_ptr<Material<D>>> srf_strong_;  // their materials during the trials
  typename Simulation<D>::GoodState srf_mechanism_;       // the lowest failed trial's end state
  long srf_steps_ = 0;
  void check_strength_reduction(Diagnostics& diag);
  nlohmann::json srf_trial(const typename Simulation<D>::GoodState& start, double F);
  /// The bisection after the last stage: summary.json's strength_reduction record. The model
  /// is back in its static state with its full strength afterwards.
  nlohmann::json strength_reduction();

  // The loop and summary.json (runner.cpp).
  nlohmann::json base_summary() const;
  nlohmann::json reaction_summary() const;
  nlohmann::json rigid_summary() const;
  std::vector<double> nearest_node(const Params& probe, Diagnostics& diag) const;
  /// The particle count of every set over all ranks (collective under mpirun).
  double global_particles() const {
    double n = double(sim_->num_particles());
    sim_->ranks->sum(&n, 1);
    return n;
  }
  /// summary.json's profile_seconds_by_rank under mpirun: every rank's seconds per phase
  /// (collective; the ranks time the same phases).
  void profile_by_rank(nlohmann::json& summary) const;
  RunResult loop();

  // The loop's parts (runner.cpp), in the order loop() calls them.
  /// How the stage loop ended: what stopped it, if anything.
  struct LoopEnd {
    std::string failure;           // an unstable step, a collapsed time step, max_steps
    int interrupted = 0;           // the signal that stopped the run (InterruptGuard)
    bool budget = false;           // --max-steps reached
    std::string stopped_by_stage;  // a stage that did not reach static (if_not_static: stop)
    std::string write_error;       // the first output that could not be written (exit 4)
    bool resumable = false;        // the interruption left a checkpoint
  };
  LoopEnd end_;
  /// When outputs are due: the running stage's frame interval, the history's, checkpoints.
  struct OutputSchedule {
    long every_steps = 0, history_every = 0;
    double every_time = 0, min_dt_ratio = 0;
    std::chrono::steady_clock::time_point last_checkpoint;
  };
  OutputSchedule schedule_;
  /// The progress lines: when the run began, the last line and its step.
  struct Progress {
    std::chrono::steady_clock::time_point start, last;
    long steps = 0;
  };
  Progress progress_;
  bool keep_good_image_ = false;  // checkpoints of the last good state are possible
  /// What the coming step's end writes.
  struct Due {
    bool frame = false, last = false, checkpoint = false;
  };
  /// Runs `write`; a failed write is recorded in end_.write_error (serially, later writes are
  /// then skipped).
  template <class F>
  void guarded(F&& write);
  /// Restores a checkpoint (or takes the initial energies), opens the outputs, first frame.
  void start_loop();
  void begin_stage(int k);
  void run_stages();
  /// One step of a stage; false when the stage (or the run) stops after it.
  bool take_step(const Stage<D>& stage, double t_end, bool& reached_static);
  /// The stable time step, cut at the stage's end (0 with end_.failure when it collapsed).
  double next_dt(double t_end);
  Due outputs_due(double dt, double t_end);
  void write_due(const Due& due);
  void report_progress();
  /// The stage's record and, when it did not reach static, the warning and its consequence.
  void end_stage(int k, bool stopped, bool reached_static);
  /// summary.json's strength_reduction record (null when not asked for).
  nlohmann::json run_strength_reduction();
  void write_interrupted_state(const nlohmann::json& srf);
  /// summary.json: `wall` this rank's wall time, `wall_max` the slowest rank's.
  nlohmann::json run_summary(double wall, double wall_max, double particles);
  void summarise_masses(nlohmann::json& summary) const;
  nlohmann::json verify_summary();
  void record_failure(RunResult& res);
  void record_interruption(RunResult& res) const;
  void close_outputs(RunResult& res);
  void drop_resume_checkpoints(const RunResult& res);
};

}  // namespace detail
}  // namespace loam
