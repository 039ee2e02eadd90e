// Run contract: output files, probes, the unstable-run stop (exit 3), overrides in the summary.
#include <catch2/catch.hpp>
#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "cli.hpp"
#include "framework/boundary.hpp"
#include "sim_helpers.hpp"

using loam_test::run_loam;
using loam_test::slurp;
using loam_test::TempDir;

TEST_CASE("a run writes XDMF frames, probes, history and a complete summary", "[output]") {
  TempDir dir("output");
  auto r =
      run_loam(std::string("run ") + LOAM_SOURCE_DIR +
               "/configs/vibrating_bar.yaml --quiet --set time.end=20 --out " + dir.path.string());
  REQUIRE(r.exit_code == 0);
  auto s = nlohmann::json::parse(slurp(dir.path / "summary.json"));
  for (const char* key :
       {"loam_version", "git_commit", "config", "dimension", "particles", "cells", "steps",
        "end_time", "wall_seconds", "threads", "particle_steps_per_second", "verify"})
    CHECK(s.contains(key));
  CHECK(s["config"]["time"]["end"].get<double>() == 20.0);  // echo after overrides
  CHECK(s["config"]["scheme"]["update"] == "musl");         // and with defaults filled in
  CHECK(s["end_time"].get<double>() == Approx(20.0));
  // Frames every 1 s for 20 s, plus t = 0.
  std::string xdmf = slurp(dir.path / "particles.xdmf");
  size_t frames = 0;
  for (size_t pos = 0; (pos = xdmf.find("<Time Value", pos)) != std::string::npos; ++pos) ++frames;
  CHECK(frames == 21);
  CHECK(std::filesystem::exists(dir.path / "particles_000020.h5"));
  // The tip probe samples every step: a header plus steps + 1 rows.
  std::ifstream probe(dir.path / "probe_tip.csv");
  std::string header, line;
  std::getline(probe, header);
  CHECK(header == "step,time,position,velocity,displacement,stress_xx,stress_yy,stress_zz");
  long rows = 0;
  while (std::getline(probe, line)) ++rows;
  CHECK(rows == s["steps"].get<long>() + 1);
  // No temporary files are left behind.
  CHECK(!loam_test::has_tmp_files(dir.path));
  // A run without a reference still has verify: an empty map (the agreed field list).
  TempDir plain("output_plain");
  auto p = run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                    "/configs/vibrating_bar.yaml --quiet --set time.end=0.5 --set "
                    "'verify=null' --out " +
                    plain.path.string());
  std::printf("%s", p.output.c_str());
  REQUIRE(p.exit_code == 0);
  auto q = nlohmann::json::parse(slurp(plain.path / "summary.json"));
  REQUIRE(q.contains("verify"));
  CHECK(q["verify"].is_object());
  CHECK(q["verify"].empty());
}

TEST_CASE("an unstable run stops with exit 3 naming step, time, particle and field", "[output]") {
  // A fixed time step 100x above the CFL limit makes the column explode.
  TempDir dir("unstable");
  auto r = run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                    "/configs/elastic_column_1d.yaml --quiet --set time.dt=0.01 --out " +
                    dir.path.string());
  INFO(r.output);
  CHECK(r.exit_code == 3);
  std::regex pattern(
      R"(loam: error: unstable run at step \d+, t = [0-9.e+-]+ s: particle \d+ \(body 'column'\): (position|velocity|stress)\S* .*)");
  CHECK(std::regex_search(r.output, pattern));
  auto s = nlohmann::json::parse(slurp(dir.path / "summary.json"));
  CHECK(s["status"] == "unstable");
  bool failed_frame = false;
  for (const auto& e : std::filesystem::directory_iterator(dir.path))
    failed_frame =
        failed_frame || e.path().filename().string().find("_failed.h5") != std::string::npos;
  CHECK(failed_frame);
}

TEST_CASE("loam check validates without writing, plugins lists every kind", "[output]") {
  auto r = run_loam(std::string("check ") + LOAM_SOURCE_DIR + "/configs/elastic_column_3d.yaml");
  CHECK(r.exit_code == 0);
  CHECK(r.output.find("ok (3D, 5120 particles, 672 cells)") != std::string::npos);
  auto p = run_loam("plugins");
  CHECK(p.exit_code == 0);
  for (const char* kind : {"shape_function", "material", "scheme", "boundary", "load", "damping",
                           "reference", "writer"})
    CHECK(p.output.find(std::string(kind) + " — ") != std::string::npos);
  CHECK(p.output.find("E  (real, Pa, required, range (0, inf); warns outside [1000, ") !=
        std::string::npos);
  auto bad = run_loam("plugins materail");
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("did you mean 'material'?") != std::string::npos);
}

TEST_CASE("a plugin given by name only can have its parameters overridden with --set", "[output]") {
  // `shape_function: linear` is shorthand for {type: linear}; `--set shape_function.key=...`
  // used to abort inside yaml-cpp.
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/vibrating_bar.yaml";
  auto ok = run_loam("check " + cfg + " --set scheme=single_phase --set scheme.update=usl");
  CHECK(ok.exit_code == 0);
  auto bad = run_loam("check " + cfg + " --set shape_function=linear --set shape_function.foo=1");
  CHECK(bad.exit_code == 2);
  CHECK(bad.output.find("<--set shape_function=linear>:1:1: error: shape_function.foo: unknown key "
                        "'foo' (this takes no parameters)") != std::string::npos);
}

TEST_CASE("a collapsing time step stops the run early with the cause (time.min_dt_ratio)",
          "[output]") {
  // USL with linear hats on a rigidly translating block: once the leading particle passes
  // within round-off of a cell face, the node ahead has a tiny mass and f/m feeds back into the
  // stress (tests/test_invariance.cpp skips this pair for that reason); the stable step fell to
  // 1e-156 s and the run crawled on to the 1e8-step budget. It must stop when dt falls below
  // 1e-6 of the first step's (default), naming the cause, with exit code 3, within the ~100
  // steps the blow-up takes.
  TempDir dir("dt_collapse");
  std::filesystem::create_directories(dir.path);
  std::ofstream(dir.path / "block.yaml")
      << "grid: {origin: [0], extent: [2.0], cell_size: 0.05}\n"
         "scheme: {type: single_phase, update: usl}\n"
         "bodies:\n"
         "  - {name: block, generator: {type: box, min: [0.5], max: [1.0]}, particles_per_cell: "
         "2,\n"
         "     material: {type: linear_elastic, E: 1.0e7, nu: 0.0, density: 2650}, velocity: "
         "[0.5]}\n"
         "time: {end: 0.2, cfl: 0.5}\n";
  auto r = run_loam("run " + (dir.path / "block.yaml").string() + " --quiet --out " +
                    (dir.path / "out").string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 3);
  CHECK(r.output.find("the stable time step collapsed to") != std::string::npos);
  CHECK(r.output.find("below time.min_dt_ratio = 1e-06 of the first step's") != std::string::npos);
  auto s = nlohmann::json::parse(slurp(dir.path / "out" / "summary.json"));
  CHECK(s["status"] == "unstable");
  CHECK(s["steps"].get<long>() < 1000);
}

TEST_CASE("a non-finite nodal value stops the step it appears in, naming the node",
          "[output][stability]") {
  // Simulation::check_grid runs at the end of every grid update (constrain_update): a NaN or
  // inf in any phase's nodal velocity or acceleration is reported with the node, its position,
  // the phase and the component, before the transfer to the particles spreads it.
  auto sim = loam_test::make_simulation<2>(R"(
grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.25}
bodies:
  - {name: block, generator: {type: box, min: [0, 0], max: [1, 1]},
     material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000}}
time: {end: 1}
)");
  const size_t n = sim->grid.num_nodes;
  std::vector<double> v(2 * n, 0.0), a(2 * n, 0.0), m(n, 1.0);
  loam::GridUpdate u;
  u.phases[0] = {loam::NodalVector{v.data(), 2, 0}, loam::NodalVector{a.data(), 2, 0},
                 loam::NodalVector{m.data(), 1, 0}};
  sim->check_grid(u);
  CHECK(sim->failure.empty());
  v[2 * 7 + 1] = std::nan("");
  sim->check_grid(u);
  std::printf("%s\n", sim->failure.c_str());
  CHECK(sim->failure == "grid node 7 at (0.5, 0.25): velocity.y = nan after the grid update");
  sim->failure.clear();
  v[2 * 7 + 1] = 0;
  a[2 * 3] = -INFINITY;
  sim->check_grid(u);
  std::printf("%s\n", sim->failure.c_str());
  CHECK(sim->failure == "grid node 3 at (0.75, 0): acceleration.x = -inf after the grid update");
}

TEST_CASE("an unstable run writes the last state that passed the check as its last frame",
          "[output][stability]") {
  // A time step 40x above the CFL limit, checked every step: the column leaves the grid at step
  // 4. The last regular frame is the state after step 3 (the last that passed), finite and at
  // t = 0.012 s; the state at detection is the frame labelled 'failed'; summary.json and the
  // message name the good state.
  TempDir dir("last_good");
  auto r = run_loam(std::string("run ") + LOAM_SOURCE_DIR +
                    "/configs/elastic_column_1d.yaml --quiet --set time.dt=0.004 --set "
                    "numerics.check_every=1 --out " +
                    dir.path.string());
  std::printf("%s", r.output.c_str());
  CHECK(r.exit_code == 3);
  CHECK(r.output.find("the last state that passed the check (step 3, t = 0.012 s) is the last "
                      "regular frame; the state at detection was written as the frame labelled "
                      "'failed'") != std::string::npos);
  auto s = nlohmann::json::parse(slurp(dir.path / "summary.json"));
  CHECK(s["last_good"]["step"] == 3);
  CHECK(s["last_good"]["time"].get<double>() == Approx(0.012));
  const std::string xdmf = slurp(dir.path / "particles.xdmf");
  CHECK(xdmf.find("particles_000001.h5") != std::string::npos);
  CHECK(xdmf.find("<Time Value=\"0.012") != std::string::npos);
  const auto x = loam_test::read_frame_doubles(dir.path / "particles_000001.h5", "position");
  REQUIRE(!x.empty());
  for (double xi : x) CHECK(std::isfinite(xi));
  double x_max = 0;
  for (size_t i = 0; i < x.size(); i += 3) x_max = std::max(x_max, x[i]);
  CHECK(x_max <= 10.5);  // inside the grid: the state before the particle left
  CHECK(std::filesystem::exists(dir.path / "particles_000002_failed.h5"));
}

TEST_CASE("a file that cannot be written stops the run with exit 4, naming it, the rest intact",
          "[output][write_failure]") {
  // A file size limit of 64 KiB (ulimit -f; works for root too, unlike a read-only directory):
  // the XDMF index outgrows it after ~58 frames (a sparse history stays below it). Exit 4, the
  // message names the file and the OS error; the frames the index lists, the history and
  // summary.json (status write_failed) are complete; no .tmp file is left.
  TempDir dir("write_failure");
  const int code = loam_test::run_bash(
      "ulimit -f 64; " + std::string(LOAM_EXE) + " run " + LOAM_SOURCE_DIR +
      "/configs/vibrating_bar.yaml --quiet --threads 1 --set time.end=1e5 --set \"probes=[]\" "
      "--set output.history_every=1000 --out " +
      dir.path.string() + " 2>" + dir.path.string() + ".err");
  const std::string err = slurp(dir.path.string() + ".err");
  std::printf("exit %d: %s", code, err.c_str());
  CHECK(code == 4);
  CHECK(err.rfind("loam: error: cannot write " + (dir.path / "particles.xdmf").string() +
                      ": File too large; the run stopped at step ",
                  0) == 0);
  CHECK(err.find("(the frames, history and probes written before are intact)") !=
        std::string::npos);
  auto s = nlohmann::json::parse(slurp(dir.path / "summary.json"));
  CHECK(s["status"] == "write_failed");
  const std::string xdmf = slurp(dir.path / "particles.xdmf");
  long frames = 0;
  for (size_t p = 0; (p = xdmf.find("<Time Value", p)) != std::string::npos; ++p) ++frames;
  CHECK(frames >= 10);
  for (long f = 0; f < frames; ++f) {
    char name[64];
    std::snprintf(name, sizeof name, "particles_%06ld.h5", f);
    CHECK(!loam_test::read_frame_doubles(dir.path / name, "position").empty());
  }
  std::ifstream hist(dir.path / "history.csv");
  std::string line, last;
  long rows = 0;
  while (std::getline(hist, line)) last = line, ++rows;
  CHECK(rows > 1);
  CHECK(std::stol(last.substr(0, last.find(','))) <= s["steps"].get<long>());
  CHECK(!loam_test::has_tmp_files(dir.path));
  std::filesystem::remove(dir.path.string() + ".err");
}

TEST_CASE(
    "started as one of several MPI ranks, compare and bench refuse, and run without the MPI "
    "build, writing nothing",
    "[output][mpi]") {
  // framework/launch.hpp: the launcher's environment (OpenMPI's OMPI_COMM_WORLD_SIZE, Hydra's
  // PMI_SIZE) gives the rank count; with more than one rank every copy would do the whole job
  // into the same output (the MPI tier runs the same under a real mpirun -np 2). `loam run`
  // runs on ranks in the MPI build (whose loam would start MPI here: its tests use a real
  // mpirun), so its refusal and the one-rank case are checked in the build without MPI.
  const std::string cfg = std::string(LOAM_SOURCE_DIR) + "/configs/vibrating_bar.yaml";
  for (const std::string env : {"OMPI_COMM_WORLD_SIZE=2", "PMI_SIZE=4"}) {
    CHECK(loam_test::run_bash(env + " " + LOAM_EXE + " bench --steps 1 2>/dev/null") == 2);
    CHECK(loam_test::run_bash(env + " " + LOAM_EXE + " compare " + cfg + " 2>/dev/null") == 2);
  }
#ifndef LOAM_MPI_BUILD
  for (const std::string env : {"OMPI_COMM_WORLD_SIZE=2", "PMI_SIZE=4"}) {
    TempDir dir("mpi_refused");
    std::filesystem::remove_all(dir.path);
    const std::string err = dir.path.string() + ".err";
    const int code =
        loam_test::run_bash(env + " " + LOAM_EXE + " run " + cfg + " --quiet --threads 1 --out " +
                            dir.path.string() + " 2>" + err);
    const std::string text = slurp(err);
    std::printf("%s loam run: exit %d: %s", env.c_str(), code, text.c_str());
    CHECK(code == 2);
    CHECK(text.find("error: loam run was started as one of ") == 0);
    CHECK(text.find("docs/parallel.md") != std::string::npos);
    CHECK(!std::filesystem::exists(dir.path));
    CHECK(text.find("tools/setup.sh --mpi") != std::string::npos);
    std::filesystem::remove(err);
  }
  // One rank (mpirun -np 1) runs as usual.
  TempDir one("mpi_one_rank");
  CHECK(loam_test::run_bash("OMPI_COMM_WORLD_SIZE=1 " + std::string(LOAM_EXE) + " run " + cfg +
                            " --quiet --threads 1 --set time.end=0.2 --overwrite --out " +
                            one.path.string()) == 0);
  CHECK(std::filesystem::exists(one.path / "summary.json"));
#endif
}
