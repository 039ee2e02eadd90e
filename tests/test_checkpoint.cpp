// Checkpoint and resume (docs/runs.md, Checkpoints and Resume; framework/checkpoint.hpp,
// runner.cpp): a run resumed from a checkpoint taken between two output frames gives bitwise the
// frames, history, probes, XDMF index and summary numbers of the uninterrupted run, for
// single_phase, two_phase_single_point and two_phase_double_point, and across thread counts; an
// interrupted run (SIGINT through a real process) resumes to the uninterrupted final state; a
// checkpoint of another configuration is refused; `keep` keeps the newest N.
#include <catch2/catch.hpp>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <initializer_list>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;

/// Every output file of run a equals run b's: frames (all datasets the test reads), history,
/// probes, the XDMF index, and the summary's numbers (all keys but the wall-clock ones and the
/// config file's path).
void require_same_outputs(const fs::path& a, const fs::path& b, long min_frames = 3) {
  long frames = 0;
  for (const auto& e : fs::directory_iterator(a)) {
    const std::string n = e.path().filename().string();
    const std::string ext = e.path().extension().string();
    if (ext == ".csv" || ext == ".xdmf") {
      INFO(n);
      CHECK(loam_test::slurp(e.path()) == loam_test::slurp(b / n));
    } else if (ext == ".h5" && n.rfind("checkpoint_", 0) != 0) {
      ++frames;
      for (const char* field : {"position", "velocity", "stress", "pore_pressure", "porosity"}) {
        INFO(n << " " << field);
        CHECK(loam_test::read_frame_doubles(e.path(), field) ==
              loam_test::read_frame_doubles(b / n, field));
      }
      CHECK(loam_test::read_frame_ids(e.path()) == loam_test::read_frame_ids(b / n));
    }
  }
  CHECK(frames >= min_frames);
  auto sa = nlohmann::json::parse(loam_test::slurp(a / "summary.json"));
  auto sb = nlohmann::json::parse(loam_test::slurp(b / "summary.json"));
  for (const char* k :
       {"wall_seconds", "particle_steps_per_second", "profile_seconds", "config_file", "threads"})
    sa.erase(k), sb.erase(k);
  CHECK(sa == sb);
}

/// Run `config` with checkpoints every `every` steps into a, copy a to b without its summary,
/// resume b from the checkpoint of step `from`, compare.
void check_resume_once(const std::string& config, const std::string& extra, long every, long from,
                       const std::string& run_only = "", const std::string& resume_only = "") {
  loam_test::TempDir a("ckpt_a"), b("ckpt_b");
  const std::string ck =
      " --set 'output.checkpoint={every_steps: " + std::to_string(every) + ", keep: 100}' ";
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/" + config;
  auto r = loam_test::run_loam("run " + cfg + " --quiet --out " + a.path.string() + ck + extra +
                               " " + run_only);
  REQUIRE(r.exit_code == 0);
  fs::copy(a.path, b.path, fs::copy_options::recursive);
  fs::remove(b.path / "summary.json");
  char name[64];
  std::snprintf(name, sizeof name, "checkpoint_%08ld.h5", from);
  REQUIRE(fs::exists(b.path / name));
  auto s = loam_test::run_loam("run " + cfg + " --quiet --resume " + (b.path / name).string() + ck +
                               extra + " " + resume_only);
  INFO(s.output);
  REQUIRE(s.exit_code == 0);
  std::printf("resume %s %s from step %ld: compared\n", config.c_str(), extra.c_str(), from);
  require_same_outputs(a.path, b.path);
  // Checkpoints from beyond the resumed one were rewritten by the resumed run, the rest kept.
  CHECK(loam_test::slurp(a.path / name).size() > 0);
}

/// check_resume_once on 1 thread. A run has the same bits on any number of threads
/// (framework/partition.hpp; tests/test_bit_identical.cpp), and a checkpoint taken on one thread
/// count resumes bitwise on another (the test below), so one thread count covers the others;
/// one thread leaves the other core to the next test.
void check_resume(const std::string& config, const std::string& extra, long every, long from) {
  check_resume_once(config, "--threads 1 " + extra, every, from);
}

}  // namespace

TEST_CASE("a resumed single-phase run is bitwise the uninterrupted one", "[checkpoint]") {
  // configs/vibrating_bar.yaml: 10 100 steps, frames every 101 steps; the checkpoint of step
  // 7 500 lies between two frames. Its reference (vibrating_bar) carries state (crossings).
  check_resume("vibrating_bar.yaml", "", 500, 7500);
}

TEST_CASE("a run checkpointed on 2 threads resumes on 1 thread bitwise, and the other way",
          "[checkpoint]") {
  // The slabs and their order do not depend on the thread count (framework/partition.hpp), so
  // the checkpoint's partition is kept and the resumed run has the uninterrupted run's bits.
  check_resume_once("granular_collapse_2d.yaml", "--set time.end=0.2 --set output.every_time=0.05",
                    100, 200, "--threads 2", "--threads 1");
  check_resume_once("seed001_terzaghi_2d.yaml", "--set time.end=0.02 --set output.every_time=0.005",
                    50, 100, "--threads 1", "--threads 2");
}

TEST_CASE("a resumed APIC run (affine_moment) is bitwise the uninterrupted one",
          "[checkpoint][apic]") {
  // configs/granular_collapse_2d.yaml on 0.02 m cells with transfer: apic and gimp to t = 0.5 s
  // (3430 steps, the column still flowing): the checkpoint of step 2000 carries every
  // particle's B_p.
  check_resume("granular_collapse_2d.yaml",
               "--set grid.cell_size=0.02 --set shape_function=gimp --set "
               "scheme.transfer=apic --set scheme.flip=1 --set time.end=0.5",
               1000, 2000);
}

TEST_CASE("a resumed run continues its energy balance bitwise", "[checkpoint][energy]") {
  // configs/granular_collapse_2d.yaml (flip 0.98: every term of the ledger but loads and drag
  // moves) to t = 0.3 s with output.energy_balance: the checkpoint carries the ledger's sums,
  // so history.csv's balance columns and summary.json's energy_balance match the uninterrupted
  // run's bit for bit.
  check_resume("granular_collapse_2d.yaml",
               "--set output.energy_balance=true --set time.end=0.3 --set output.every_time=0.05",
               500, 1000);
}

TEST_CASE("a resumed contact run is bitwise the uninterrupted one", "[checkpoint][contact]") {
  // configs/contact_block_incline_2d.yaml to 0.3 s (about 3100 steps) with the energy balance:
  // the bodies' fields are rebuilt every step, so the checkpoint needs nothing of them; the
  // ledger's dissipation_contact continues.
  check_resume("contact_block_incline_2d.yaml",
               "--set time.end=0.3 --set output.energy_balance=true", 1000, 2000);
}

TEST_CASE("a resumed run with a rigid body under contact is bitwise the uninterrupted one",
          "[checkpoint][contact][rigid]") {
  // configs/granular_barrier_2d.yaml to 0.4 s with the energy balance, resumed from step 6000
  // (0.33 s, as the front reaches the wall): the rigid body's mass, centre, inertia and motion
  // are rebuilt from its particles every step, so the checkpoint needs nothing of them.
  check_resume("granular_barrier_2d.yaml",
               "--set time.end=0.4 --set output.energy_balance=true --set output.every_time=0.1",
               2000, 6000);
}

TEST_CASE("a resumed F-bar run is bitwise the uninterrupted one", "[checkpoint][locking]") {
  // configs/strip_footing_contact_2d.yaml with volumetric: fbar to 1 s (about 1000 steps): the
  // averaged volume change and mean stress are rebuilt every step from the particles, so the
  // checkpoint needs nothing of them (clay and the rigid footing on their own fields).
  check_resume("strip_footing_contact_2d.yaml",
               "--set scheme.volumetric=fbar --set time.end=1 --set output.every_time=0.25", 200,
               600);
}

TEST_CASE("a resumed two-phase run is bitwise the uninterrupted one", "[checkpoint]") {
  // configs/seed001_terzaghi.yaml (two_phase_single_point, terzaghi reference) to t = 0.05 s
  // (7430 steps; frames every 0.01 s), resumed from step 4000.
  check_resume("seed001_terzaghi.yaml", "--set time.end=0.05 --set output.every_time=0.01", 1000,
               4000);
}

TEST_CASE("a run resumed within a stage is bitwise the uninterrupted one", "[checkpoint][stages]") {
  // configs/construction_column_1d.yaml: stages settle (steps 1-400), build (the upper body
  // activated; to step 1710) and excavate (deactivated). The checkpoint of step 1000 lies
  // within the build stage: the resumed run must neither activate the body again nor lose the
  // stage's static window, records or plugins.
  check_resume("construction_column_1d.yaml", "", 500, 1000);
}

TEST_CASE(
    "a resumed piping run (reservoir, sink, a series reference) is bitwise the uninterrupted one",
    "[checkpoint][piping]") {
  // configs/seed000_piping.yaml on 0.25 m cells to t = 1 s: the rising reservoir creates and
  // the region sink removes liquid points (ids, the mass balance), and sheet_pile_seepage
  // accumulates its time series (verify.series, verify.csv) across the checkpoint. 2D, so at 2
  // threads points of same-coloured slabs do share cells after the move.
  // 0.25 m cells have no node line inside the pile: its grains' vertical hold goes on the tip
  // (as tests/test_piping.cpp's quick scene).
  check_resume("seed000_piping.yaml",
               "--set grid.cell_size=0.25 --set time.end=1 --set output.every_time=0.25 --set "
               "'boundaries.4={type: slip, min: [4, 3], max: [4.25, 3], directions: [y], phase: "
               "solid}'",
               500, 1500);
}

TEST_CASE("a resumed double-point run is bitwise the uninterrupted one",
          "[checkpoint][double_point]") {
  // Its cell sums after the move run in point order (framework/cell_sums.hpp), so 2 threads are
  // deterministic too.
  check_resume("terzaghi_double_point.yaml", "--set time.end=0.05 --set output.every_time=0.01",
               1000, 4000);
}

TEST_CASE("a resumed blast (absorbing free_field faces, blast_wave) is bitwise the same",
          "[checkpoint][blast]") {
  // configs/seed002_blast_3d.yaml on 2 m cells to 0.01 s (25 steps): the absorbing faces'
  // free-field reactions of the first step and the reference's probe series cross the
  // checkpoint of step 10.
  check_resume("seed002_blast_3d.yaml",
               "--set grid.cell_size=2 --set time.end=0.01 --set output.every_time=0.002", 5, 10);
}

TEST_CASE("an unstable run checkpoints its last good state and resuming it fails the same way",
          "[checkpoint][stability]") {
  // The seed-001 column with USL, k = 10 m/s and cfl 0.8 (above its critical 0.755,
  // test_two_phase_mechanism.cpp) diverges at step 77, 2 threads. Checked every 10 steps and
  // checkpointed every 50: the state after step 70 passed the last check, and is written as
  // checkpoint_00000070.h5 beside the regular checkpoint of step 50 and named in the message
  // and summary.json. Resumed from it, the run diverges at the same step with bitwise the same
  // frames (the failed one included), history and summary: the checkpoint holds the particles,
  // partition and run state of step 70, not a mix with the state at detection.
  loam_test::TempDir a("lastgood_a"), b("lastgood_b");
  const std::string args = std::string("run ") + LOAM_SOURCE_DIR +
                           "/configs/seed001_terzaghi.yaml --quiet --threads 2 --set time.end=0.1 "
                           "--set scheme.update=usl --set scheme.drag.hydraulic_conductivity=10 "
                           "--set output.every_time=0.01 --set time.cfl=0.8 "
                           "--set 'output.checkpoint={every_steps: 50, keep: 5}' ";
  auto r = loam_test::run_loam(args + "--out " + a.path.string());
  std::printf("%s", r.output.c_str());
  REQUIRE(r.exit_code == 3);
  CHECK(r.output.find("unstable run at step 77") != std::string::npos);
  CHECK(r.output.find("the last state that passed the check (step 70, t = ") != std::string::npos);
  CHECK(r.output.find(" s) is the last regular frame and checkpoint_00000070.h5; the state at "
                      "detection was written as the frame labelled 'failed'") != std::string::npos);
  auto sa = nlohmann::json::parse(loam_test::slurp(a.path / "summary.json"));
  CHECK(sa["last_good"]["step"] == 70);
  CHECK(sa["last_good"]["checkpoint"] == "checkpoint_00000070.h5");
  CHECK(fs::exists(a.path / "checkpoint_00000050.h5"));
  REQUIRE(fs::exists(a.path / "checkpoint_00000070.h5"));
  fs::copy(a.path, b.path, fs::copy_options::recursive);
  fs::remove(b.path / "summary.json");
  auto s = loam_test::run_loam(args + "--resume " + (b.path / "checkpoint_00000070.h5").string());
  std::printf("resumed from step 70: exit %d\n", s.exit_code);
  CHECK(s.exit_code == 3);
  CHECK(s.output == r.output);
  require_same_outputs(a.path, b.path, 2);
}

namespace {

/// Run `cfg` (with `args`) into a uninterrupted, then into b with SIGINT once b's frame
/// `frame` exists and `delay` seconds more: the interrupted run's exit code.
int run_then_interrupt(const std::string& cfg, const std::string& args, const fs::path& a,
                       const fs::path& b, const std::string& frame, double delay) {
  REQUIRE(loam_test::run_loam("run " + cfg + " --out " + a.string() + args).exit_code == 0);
  return loam_test::run_bash(std::string(LOAM_EXE) + " run " + cfg + " --out " + b.string() + args +
                             " & pid=$!; while [ ! -e " + (b / frame).string() +
                             " ] && kill -0 $pid 2>/dev/null; do sleep 0.01; done; sleep " +
                             std::to_string(delay) + "; kill -INT $pid; wait $pid");
}

/// `--resume b` to the end: the summaries of the uninterrupted run a and of the resumed b.
std::pair<nlohmann::json, nlohmann::json> resume_to_end(const std::string& cfg,
                                                        const std::string& args, const fs::path& a,
                                                        const fs::path& b) {
  auto r = loam_test::run_loam("run " + cfg + " --resume " + b.string() + args);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  auto sa = nlohmann::json::parse(loam_test::slurp(a / "summary.json"));
  auto sb = nlohmann::json::parse(loam_test::slurp(b / "summary.json"));
  CHECK(sb["status"] == "ok");
  return {sa, sb};
}

/// The last frames of runs a and b (summaries sa, sb) hold the same `fields`, bit for bit.
void check_same_last_frame(const fs::path& a, const nlohmann::json& sa, const fs::path& b,
                           const nlohmann::json& sb, std::initializer_list<const char*> fields) {
  char last_a[64], last_b[64];
  std::snprintf(last_a, sizeof last_a, "particles_%06ld.h5", sa["frames"].get<long>() - 1);
  std::snprintf(last_b, sizeof last_b, "particles_%06ld.h5", sb["frames"].get<long>() - 1);
  for (const char* field : fields)
    CHECK(loam_test::read_frame_doubles(a / last_a, field) ==
          loam_test::read_frame_doubles(b / last_b, field));
}

}  // namespace

TEST_CASE("an interrupted run resumes to the uninterrupted run's final state",
          "[checkpoint][interrupt]") {
  // SIGINT 0.5 s after the first frame writes a checkpoint with the last frame; `--resume DIR`
  // finishes the run. The final frame, history and summary numbers equal those of a run never
  // interrupted (the frames in between differ only in their number: the interruption added one).
  loam_test::TempDir a("ckpt_int_a"), b("ckpt_int_b");
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/vibrating_bar.yaml";
  const std::string args =
      " --quiet --threads 1 --set time.end=5000 --set output.every_time=500 "
      "--set \"output.checkpoint={every_steps: 20000}\"";
  const int code = run_then_interrupt(cfg, args, a.path, b.path, "particles_000000.h5", 0.5);
  auto interrupted = nlohmann::json::parse(loam_test::slurp(b.path / "summary.json"));
  std::printf("interrupted at step %ld (exit %d); resuming\n", interrupted["steps"].get<long>(),
              code);
  REQUIRE(code == 130);
  const auto [sa, sb] = resume_to_end(cfg, args, a.path, b.path);
  for (const char* k : {"steps", "end_time", "energy_final", "verify", "mass", "dt_min", "dt_max"})
    CHECK(sa[k] == sb[k]);
  check_same_last_frame(a.path, sa, b.path, sb, {"position", "velocity", "stress"});
  // The history has one row more (the interruption's step, unless it is a multiple of the
  // config's history_every of 10 steps, whose row is regular) and otherwise the same rows.
  std::ifstream ha(a.path / "history.csv"), hb(b.path / "history.csv");
  std::vector<std::string> rows_a, rows_b;
  for (std::string l; std::getline(ha, l);) rows_a.push_back(l);
  for (std::string l; std::getline(hb, l);) rows_b.push_back(l);
  CHECK(rows_a.back() == rows_b.back());
  CHECK(rows_b.size() == rows_a.size() + (interrupted["steps"].get<long>() % 10 != 0 ? 1 : 0));
}

TEST_CASE(
    "a checkpoint of another configuration, a missing one and an unsupported reference "
    "are refused",
    "[checkpoint][cli]") {
  loam_test::TempDir a("ckpt_refuse");
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/vibrating_bar.yaml";
  const std::string ck = " --set 'output.checkpoint={every_steps: 2000, keep: 2}'";
  REQUIRE(loam_test::run_loam("run " + cfg + " --quiet --threads 1 --out " + a.path.string() + ck)
              .exit_code == 0);
  // keep: 2 leaves the two newest of the five checkpoints.
  long kept = 0;
  for (const auto& e : fs::directory_iterator(a.path))
    kept += e.path().filename().string().rfind("checkpoint_", 0) == 0;
  CHECK(kept == 2);
  CHECK(fs::exists(a.path / "checkpoint_00010000.h5"));
  auto other = loam_test::run_loam("run " + cfg + " --quiet --resume " + a.path.string() + ck +
                                   " --set grid.cell_size=0.5");
  std::printf("%s", other.output.c_str());
  CHECK(other.exit_code == 2);
  CHECK(other.output.find("belongs to another configuration") != std::string::npos);
  auto keep_only = loam_test::run_loam("run " + cfg + " --quiet --out " + (a.path / "k").string() +
                                       " --set 'output.checkpoint={keep: 3}'");
  std::printf("%s", keep_only.output.c_str());
  CHECK(keep_only.exit_code == 2);
  CHECK(keep_only.output.find(":1:1: error: output.checkpoint: give every_steps or "
                              "every_wall_seconds (or both)") != std::string::npos);
  CHECK(!fs::exists(a.path / "k"));
  auto none =
      loam_test::run_loam("run " + cfg + " --quiet --resume " + (a.path / "nothing").string() + ck);
  CHECK(none.exit_code == 2);
  CHECK(none.output.find("no such directory or checkpoint file") != std::string::npos);
  // A reference without save_state (tests/plugins/stateless_reference.cpp, loaded as an
  // out-of-tree plugin): it runs, but a checkpointed run with it is refused before any output.
  std::string bar = loam_test::slurp(cfg);
  bar = "plugins: [" + std::string(LOAM_STATELESS_REFERENCE) + "]\n" +
        bar.substr(0, bar.find("verify:")) + "verify: {type: test_peak_speed}\n";
  const fs::path run_file = a.path / "stateless.yaml";
  std::ofstream(run_file) << bar;
  auto plain = loam_test::run_loam("run " + run_file.string() + " --quiet --threads 1 --out " +
                                   (a.path / "plain").string());
  INFO(plain.output);
  REQUIRE(plain.exit_code == 0);
  auto sp = nlohmann::json::parse(loam_test::slurp(a.path / "plain" / "summary.json"));
  CHECK(sp["verify"]["peak_speed"].get<double>() > 0.09);  // v0 = 0.1 m/s at t = 0
  auto refused = loam_test::run_loam("run " + run_file.string() + " --quiet --out " +
                                     (a.path / "refused").string() + ck);
  std::printf("%s", refused.output.c_str());
  CHECK(refused.exit_code == 2);
  CHECK(refused.output.find(": error: output.checkpoint: the reference 'test_peak_speed' cannot "
                            "be checkpointed yet (its state is not saved)") != std::string::npos);
  CHECK(!fs::exists(a.path / "refused"));
}

TEST_CASE(
    "a resumed slope failure (slope_failure's per-point state) is bitwise the same, 1 and 2 "
    "threads",
    "[checkpoint][slope]") {
  // The quick variant of configs/seed002_slope_frictional.yaml (1 m cells), resumed at step
  // 5000, inside the stage after the strength drop: slope_failure carries every point's last
  // position and last fast sample (time_to_rest) and its series across the checkpoint.
  check_resume("seed002_slope_frictional.yaml",
               "--set grid.cell_size=1 --set stages.3.duration=10"
               " --set stages.0.static_speed=1e-4 --set stages.1.static_speed=1e-4",
               500, 5000);
}

TEST_CASE("Ctrl-C on the default scene without output.checkpoint resumes to the same final frame",
          "[checkpoint][interrupt]") {
  // A run interrupted by SIGINT always writes a checkpoint (one file, also without
  // output.checkpoint); `--resume DIR` finishes the run, and its final frame is bitwise that of
  // the run never interrupted; the resumed run, not asked to keep checkpoints, removes it.
  loam_test::TempDir a("ckpt_ctrl_c_a"), b("ckpt_ctrl_c_b");
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/granular_collapse_2d.yaml";
  const std::string args = " --quiet --threads 1";
  const int code = run_then_interrupt(cfg, args, a.path, b.path, "particles_000002.h5", 0);
  REQUIRE(code == 130);
  long checkpoints = 0;
  for (const auto& e : fs::directory_iterator(b.path))
    checkpoints += e.path().filename().string().rfind("checkpoint_", 0) == 0;
  auto interrupted = nlohmann::json::parse(loam_test::slurp(b.path / "summary.json"));
  std::printf("granular collapse interrupted at step %ld: %ld checkpoint file(s); resuming\n",
              interrupted["steps"].get<long>(), checkpoints);
  CHECK(checkpoints == 1);
  const auto [sa, sb] = resume_to_end(cfg, args, a.path, b.path);
  CHECK(sa["steps"] == sb["steps"]);
  CHECK(sa["verify"] == sb["verify"]);
  check_same_last_frame(a.path, sa, b.path, sb,
                        {"position", "velocity", "stress", "plastic_strain_eq"});
  long left = 0;
  for (const auto& e : fs::directory_iterator(b.path))
    left += e.path().filename().string().rfind("checkpoint_", 0) == 0;
  CHECK(left == 0);
}

TEST_CASE("a staged run interrupted inside a stage resumes to the uninterrupted stages",
          "[checkpoint][interrupt][stages]") {
  // The interrupt checkpoint of a staged run leaves the interrupted stage's record out (the
  // resumed run writes the stage's own), as a periodic checkpoint inside a stage does: the
  // resumed run's stages[] and final frame equal the uninterrupted run's. Kept in the image,
  // the record "interrupted" came back with the checkpoint and the stage was listed twice.
  loam_test::TempDir a("ckpt_stages_a"), b("ckpt_stages_b"), c("ckpt_stages_cfg");
  fs::create_directories(c.path);
  const fs::path cfg = c.path / "staged.yaml";
  std::ofstream(cfg) << "grid: {extent: [1.2], cell_size: 0.02}\n"
                        "bodies:\n"
                        "  - name: soil\n"
                        "    generator: {type: box, min: [0], max: [1]}\n"
                        "    material: {type: linear_elastic, E: 1.0e6, nu: 0, density: 1000}\n"
                        "selections:\n"
                        "  - {name: top, min: [0.99], max: [1]}\n"
                        "boundaries:\n"
                        "  - {type: fixed, face: x-}\n"
                        "damping: {type: local, alpha: 0.1}\n"
                        "output: {every_time: 10, fields: [velocity, stress]}\n"
                        "stages:\n"
                        "  - {name: rest, duration: 60}\n"
                        "  - {name: load, duration: 60,\n"
                        "     loads: [{type: traction, selection: top, face: x+, traction: "
                        "[-1000]}]}\n";
  const std::string args = " --quiet --threads 1";
  const int code =
      run_then_interrupt(cfg.string(), args, a.path, b.path, "particles_000002.h5", 0.2);
  REQUIRE(code == 130);
  auto interrupted = nlohmann::json::parse(loam_test::slurp(b.path / "summary.json"));
  std::printf("staged run interrupted at t = %.3f s in stage %zu; resuming\n",
              interrupted["end_time"].get<double>(), interrupted["stages"].size());
  const auto [sa, sb] = resume_to_end(cfg.string(), args, a.path, b.path);
  REQUIRE(sa["stages"].size() == 2);
  REQUIRE(sb["stages"].size() == 2);
  for (size_t k = 0; k < 2; ++k)
    for (const char* key : {"name", "status", "start_time", "end_time", "steps", "energy"})
      CHECK(sa["stages"][k][key] == sb["stages"][k][key]);
  check_same_last_frame(a.path, sa, b.path, sb, {"position", "velocity", "stress"});
}
