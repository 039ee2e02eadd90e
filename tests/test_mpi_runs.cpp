// Whole runs under mpirun (issue 18, docs/parallel.md "Tests"): `mpirun -np N loam run` at 1, 2
// and 4 ranks against the serial run of the same scene, for every shape function that runs on
// ranks, in 1D, 2D and 3D, with particles crossing the cuts between the blocks in every
// direction. Only in the MPI build (its loam runs on ranks).
#ifdef LOAM_MPI_BUILD

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "cli.hpp"

namespace {

namespace fs = std::filesystem;
using loam_test::TempDir;

/// `loam run` of dir/run.yaml into dir/<out>: serially (ranks 0) or under mpirun -np ranks.
/// OpenMPI as root (CI) needs the two ALLOW_RUN_AS_ROOT variables, 4 ranks on 2 cores
/// --oversubscribe; containers may forbid cross-memory attach (single_copy_mechanism); a rank
/// waiting in MPI yields its core (yield_when_idle: ctest runs other tests beside it).
loam_test::CliResult run_on(const fs::path& dir, const std::string& out, int ranks,
                            const std::string& args = "") {
  std::string launch;
  if (ranks > 0)
    launch =
        "OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 "
        "OMPI_MCA_btl_vader_single_copy_mechanism=none OMPI_MCA_mpi_yield_when_idle=1 " +
        std::string(LOAM_MPIEXEC) + " -np " + std::to_string(ranks) + " --oversubscribe ";
  return loam_test::run_command(launch + LOAM_EXE + " run " + (dir / "run.yaml").string() +
                                " --quiet --threads 1 --out " + (dir / out).string() + " " + args);
}

/// The particles of one frame, by id: every piece of it (particles_NNNNNN.h5 serially,
/// particles_NNNNNN_rRRRR.h5 per rank under mpirun), every dataset the frame has.
struct Frame {
  std::vector<std::string> fields;                         // the frame's datasets, but id
  std::map<int, std::vector<std::vector<double>>> values;  // id -> per field its components
  std::map<int, int> piece;                                // id -> the rank whose file holds it
  size_t count = 0;  // particles read (a duplicate id would show here)
};

fs::path frame_file(const fs::path& out, long frame, int rank) {
  char name[64];
  if (rank < 0)
    std::snprintf(name, sizeof name, "particles_%06ld.h5", frame);
  else
    std::snprintf(name, sizeof name, "particles_%06ld_r%04d.h5", frame, rank);
  return out / name;
}

/// The names of a frame's datasets.
std::vector<std::string> dataset_names(const fs::path& file) {
  std::vector<std::string> names;
  hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  REQUIRE(f >= 0);
  H5Literate(
      f, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* out) -> herr_t {
        static_cast<std::vector<std::string>*>(out)->push_back(name);
        return 0;
      },
      &names);
  H5Fclose(f);
  return names;
}

Frame read_frame(const fs::path& out, long frame, int ranks) {
  Frame fr;
  for (int r = 0; r < std::max(ranks, 1); ++r) {
    const fs::path file = frame_file(out, frame, ranks > 0 ? r : -1);
    REQUIRE(fs::exists(file));
    if (fr.fields.empty())
      for (const auto& name : dataset_names(file))
        if (name != "id") fr.fields.push_back(name);
    const std::vector<int> ids = loam_test::read_frame_ids(file);
    std::vector<std::vector<double>> cols;
    std::vector<size_t> widths;
    for (const auto& name : fr.fields) {
      cols.push_back(loam_test::read_frame_doubles(file, name));
      widths.push_back(ids.empty() ? 0 : cols.back().size() / ids.size());
      REQUIRE(cols.back().size() == ids.size() * widths.back());
    }
    for (size_t i = 0; i < ids.size(); ++i) {
      auto& v = fr.values[ids[i]];
      fr.piece[ids[i]] = r;
      for (size_t f = 0; f < fr.fields.size(); ++f) {
        const long w = long(widths[f]);
        v.emplace_back(cols[f].begin() + long(i) * w, cols[f].begin() + long(i + 1) * w);
      }
      ++fr.count;
    }
  }
  return fr;
}

/// Per field of the frames, the largest difference between two runs' particles and the largest
/// magnitude, over the frames compared so far.
struct Difference {
  std::map<std::string, std::pair<double, double>> field;  // name -> (difference, magnitude)
  bool ids_match = true;
  /// The largest difference relative to its field's largest magnitude over the run (a field
  /// that is round-off in one frame, e.g. the stress before the disks touch, is measured
  /// against what it reaches).
  double relative() const {
    double r = 0;
    for (const auto& [name, dm] : field)
      r = std::max(r, dm.second > 0 ? dm.first / dm.second : dm.first);
    return r;
  }
  void add(const Frame& a, const Frame& b) {
    if (a.count != b.count || a.values.size() != a.count || b.values.size() != b.count ||
        a.fields != b.fields) {
      ids_match = false;
      return;
    }
    for (const auto& [id, va] : a.values) {
      const auto it = b.values.find(id);
      if (it == b.values.end()) {
        ids_match = false;
        return;
      }
      for (size_t f = 0; f < a.fields.size(); ++f) {
        auto& [diff, scale] = field[a.fields[f]];
        for (size_t c = 0; c < va[f].size(); ++c) {
          scale = std::max(scale, std::fabs(va[f][c]));
          diff = std::max(diff, std::fabs(va[f][c] - it->second[f][c]));
        }
      }
    }
  }
};

/// Whether two frames hold the same particles with the same bits.
bool frames_identical(const Frame& a, const Frame& b) {
  return a.count == b.count && a.values == b.values;
}

struct Scene {
  std::string name, yaml;
  bool crosses = true;  // particles change rank at 2 and 4 ranks
};

/// Two elastic disks (spheres, a bar's halves) meeting near the centre of the grid, each moving
/// along the diagonal at another speed (the contact moves), so that their particles cross every
/// cut between the blocks, the corners included; 200 steps.
/// [x, y, y...] in dim dimensions.
std::string point_at(int dim, double x, double y) {
  std::string p = "[" + std::to_string(x);
  for (int d = 1; d < dim; ++d) p += ", " + std::to_string(y);
  return p + "]";
}
std::string node_at(int dim, int i, int j) {
  std::string p = "[" + std::to_string(i);
  for (int d = 1; d < dim; ++d) p += ", " + std::to_string(j);
  return p + "]";
}

std::string disks(int dim, const std::string& shape,
                  const std::string& scheme = "{type: single_phase, update: musl}",
                  const std::string& time = "{end: 1.0, dt: 0.005}") {
  const std::string origin = dim == 1 ? "[0]" : dim == 2 ? "[0, 0]" : "[0, 0, 0]";
  const std::string extent = dim == 1 ? "[1]" : dim == 2 ? "[1, 1]" : "[1, 1, 1]";
  auto point = [&](double c) {
    std::string p = "[";
    for (int d = 0; d < dim; ++d) p += (d ? ", " : "") + std::to_string(c);
    return p + "]";
  };
  const double cell = dim == 3 ? 0.05 : 0.025;
  return "grid: {origin: " + origin + ", extent: " + extent +
         ", cell_size: " + std::to_string(cell) + "}\nshape_function: " + shape +
         "\nscheme: " + scheme +
         "\nbodies:\n"
         "  - name: left\n    generator: {type: sphere, center: " +
         point(0.27) +
         ", radius: 0.2}\n    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "    velocity: " +
         point(0.25) + "\n  - name: right\n    generator: {type: sphere, center: " + point(0.73) +
         ", radius: 0.2}\n    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "    velocity: " +
         point(-0.15) + "\ntime: " + time +
         "\n"
         "output: {every_steps: 50, history_every: 1, history_digits: 17, fields: " +
         (scheme.find("two_phase") != std::string::npos
              ? "[velocity, stress, mass, pore_pressure, water_velocity]"
              : "[velocity, stress, mass]") +
         "}\n"
         // The particles facing each other across the middle, and the middle node.
         "probes:\n"
         "  - {name: left_front, particle_near: " +
         point_at(dim, 0.46, 0.27) +
         ", fields: [position, velocity, stress, displacement]}\n"
         "  - {name: right_front, particle_near: " +
         point_at(dim, 0.54, 0.73) +
         ", fields: [velocity, stress]}\n"
         "  - {name: middle, node: " +
         node_at(dim, int(std::lround(0.5 / cell)), int(std::lround(0.27 / cell))) +
         ", fields: [mass, velocity]}\n";
}

/// The grid, shape function, scheme and gravity of the columns, and their sand.
std::string column_setting(const std::string& shape) {
  return "grid: {origin: [0, 0], extent: [0.6, 0.3], cell_size: 0.0125}\nshape_function: " + shape +
         "\nscheme: {type: single_phase, update: musl, flip: 0.98}\ngravity: [0, -9.81]\n";
}
const char* const kSand =
    "    particles_per_cell: 2\n"
    "    material: {type: mohr_coulomb, E: 1.0e5, nu: 0.3, density: 1800, c: 0, phi: 30, psi: 0}\n";

/// A Mohr-Coulomb column collapsing along a friction floor past the cuts (granular collapse,
/// docs/verification.md; gravity, a slip wall, a friction floor, a fixed far wall, local
/// damping).
std::string column(const std::string& shape) {
  return column_setting(shape) +
         "bodies:\n  - name: sand\n    generator: {type: box, min: [0, 0], max: [0.27, 0.25]}\n" +
         kSand +
         "boundaries:\n  - {type: slip, face: x-}\n"
         "  - {type: friction, face: y-, coefficient: 0.5}\n  - {type: fixed, face: x+}\n"
         "damping: {type: local, alpha: 0.05}\n"
         "time: {end: 0.25, dt: 5.0e-4}\n"
         "output: {every_steps: 100, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass]}\n"
         "verify: {type: granular_collapse}\n";
}

/// configs/construction_column_1d.yaml undamped, each stage at most 0.06 s (then the next).
std::string staged_column_1d() {
  std::string cfg =
      loam_test::slurp(fs::path(LOAM_SOURCE_DIR) / "configs" / "construction_column_1d.yaml");
  const std::string damping = "damping: {type: local, alpha: 0.7}\n";
  REQUIRE(cfg.find(damping) != std::string::npos);
  cfg.erase(cfg.find(damping), damping.size());
  for (size_t at = 0; (at = cfg.find("max_time: 2", at)) != std::string::npos;)
    cfg.replace(at, 11, "max_time: 0.06\n    if_not_static: continue");
  return cfg + "\n";
}

/// column() in two bodies, the upper one joining in a second stage that also puts a friction
/// floor under the column; each stage until static or 0.08 s.
std::string staged_column(const std::string& shape) {
  return column_setting(shape) +
         "bodies:\n  - name: lower\n    generator: {type: box, min: [0, 0], max: [0.27, 0.15]}\n" +
         kSand +
         "  - name: upper\n    generator: {type: box, min: [0, 0.15], max: [0.27, 0.25]}\n"
         "    active: false\n" +
         kSand +
         "boundaries:\n  - {type: slip, face: x-}\n  - {type: fixed, face: y-}\n"
         "  - {type: fixed, face: x+}\n"
         "damping: {type: local, alpha: 0.05}\n"
         "time: {dt: 5.0e-4}\n"
         "output: {every_steps: 40, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass]}\n"
         "probes:\n  - {name: toe, particle_near: [0.26, 0.01], fields: [velocity, stress]}\n"
         "stages:\n  - {name: settle, until: static, max_time: 0.05, if_not_static: continue}\n"
         "  - name: build\n    until: static\n    max_time: 0.08\n    activate: [upper]\n"
         "    boundaries:\n      - {type: slip, face: x-}\n"
         "      - {type: friction, face: y-, coefficient: 0.5}\n      - {type: fixed, face: x+}\n";
}

/// The Terzaghi column of configs/seed001_terzaghi.yaml (two-phase, a traction on the top
/// particles, a drained top), 250 steps of its consolidation's start, every field of the scheme.
std::string terzaghi_1d() {
  return "grid: {origin: [0], extent: [1.0], cell_size: 0.025}\n"
         "scheme: {type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: 2.2e9,\n"
         "         drag: {type: darcy, hydraulic_conductivity: 1.0e-3}}\n"
         "bodies:\n  - name: column\n    generator: {type: box, min: [0], max: [1.0]}\n"
         "    material: {type: linear_elastic, E: 1.0e7, nu: 0.0, density: 2650}\n"
         "boundaries:\n  - {type: fixed, face: x-}\n  - {type: drained, face: x+}\n"
         "loads:\n  - {type: traction, body: column, face: x+, traction: [-1.0e4]}\n"
         "time: {end: 2.0e-3, dt: 8.0e-6}\n"
         "output: {every_steps: 50, history_every: 1, history_digits: 17,\n"
         "         fields: [velocity, stress, mass, pore_pressure, water_velocity, porosity]}\n";
}

/// `mpirun -np ranks loam run` of dir/run.yaml is refused: exit 2, every expected located
/// error in its output, no output directory.
void check_refused(const fs::path& dir, int ranks, const std::vector<std::string>& expected) {
  const auto r = run_on(dir, "out", ranks);
  std::printf("mpirun -np %d, refused: exit %d\n%s", ranks, r.exit_code, r.output.c_str());
  CHECK(r.exit_code == 2);
  for (const auto& e : expected) {
    INFO(e);
    CHECK(r.output.find(e) != std::string::npos);
  }
  CHECK(!fs::exists(dir / "out"));
}

/// history.csv's columns that the ranks must reproduce, per step.
const std::vector<std::string> kHistory = {"time",           "kinetic_energy", "strain_energy",
                                           "gravity_energy", "momentum_x",     "momentum_y",
                                           "momentum_z"};

}  // namespace

TEST_CASE("mpirun -np 1, 2 and 4: whole runs match the serial run, every shape function, 1D-3D",
          "[mpi][mpi_run]") {
  // Issue 18's acceptance: momentum and energies at every step within 1e-12 of the serial run
  // (relative to each series' largest magnitude), particle fields after 200 steps within 1e-10
  // (relative to each field's largest magnitude), the same id set and count, the same bits when
  // repeated at the same rank count, and -np 1 the serial run's bits. The ranks add the ghost
  // layer's shares in another order than the serial scatter, so they agree to round-off only.
  std::vector<Scene> scenes;
  for (const std::string shape : {"linear", "gimp", "bspline2"}) {
    for (int dim = 1; dim <= 3; ++dim)
      scenes.push_back({std::to_string(dim) + "D disks " + shape, disks(dim, shape)});
    scenes.push_back({"2D column collapse " + shape, column(shape)});
  }
  // The other update orders and the affine transfers (their nodal sums are completed after
  // each scatter as MUSL's).
  scenes.push_back({"2D disks gimp usf", disks(2, "gimp", "{type: single_phase, update: usf}")});
  scenes.push_back({"2D disks gimp usl", disks(2, "gimp", "{type: single_phase, update: usl}")});
  scenes.push_back({"2D disks bspline2 apic",
                    disks(2, "bspline2", "{type: single_phase, update: musl, transfer: apic}")});
  scenes.push_back({"2D disks gimp tpic",
                    disks(2, "gimp", "{type: single_phase, update: musl, transfer: tpic}")});
  scenes.push_back({"3D disks linear usf apic",
                    disks(3, "linear", "{type: single_phase, update: usf, transfer: apic}")});
  // Two-phase (single point): a Terzaghi column under a traction, and saturated disks (a soft
  // pore fluid, so that they move across the cuts in 400 steps).
  scenes.push_back({"1D Terzaghi two-phase", terzaghi_1d(), false});
  // Stages: configs/construction_column_1d.yaml without its damping (local damping's sign(v)
  // turns round-off at nodes near rest into differences of 1e-8, so a column damped to rest
  // matches the serial run only that far) and with stages of 0.06 s: a column under gravity, a
  // second body activated on it and removed again, each stage `until: static` (motion_speed
  // over the ranks is checked; the column keeps vibrating, so each ends at max_time), probes at
  // the base; and a 2D column whose upper body joins in a second stage with its own friction
  // floor.
  scenes.push_back({"1D construction column stages", staged_column_1d(), false});
  scenes.push_back({"2D column stages gimp", staged_column("gimp")});
  scenes.push_back(
      {"2D saturated disks gimp",
       disks(2, "gimp",
             "{type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: 1.0e4, drag: "
             "{type: darcy, hydraulic_conductivity: 1.0e-3}}",
             "{end: 0.6, dt: 0.0015}")});
  for (const Scene& scene : scenes) {
    INFO(scene.name);
    TempDir dir("mpi_run");
    fs::create_directories(dir.path);
    std::ofstream(dir.path / "run.yaml") << scene.yaml;
    const auto serial = run_on(dir.path, "serial", 0);
    INFO(serial.output);
    REQUIRE(serial.exit_code == 0);
    const auto h0 = loam_test::read_csv_columns(dir.path / "serial" / "history.csv");
    std::vector<long> frame_ids;
    for (long f = 0; fs::exists(frame_file(dir.path / "serial", f, -1)); ++f)
      frame_ids.push_back(f);
    REQUIRE(frame_ids.size() >= 5);
    const double mass = nlohmann::json::parse(loam_test::slurp(
        dir.path / "serial" / "summary.json"))["sets"]["particles"]["mass"]
                            .get<double>();
    for (int ranks : {1, 2, 4}) {
      const std::string out = "np" + std::to_string(ranks);
      const auto r = run_on(dir.path, out, ranks);
      INFO(r.output);
      REQUIRE(r.exit_code == 0);
      // Momentum and energies at every step: energies relative to the largest energy of the
      // run, momentum to sqrt(2 M E_kin) (the momentum of the whole mass at the rms speed).
      const auto h = loam_test::read_csv_columns(dir.path / out / "history.csv");
      REQUIRE(h.at("step") == h0.at("step"));
      double energy_scale = 0;
      for (const char* key : {"kinetic_energy", "strain_energy", "gravity_energy"})
        for (double x : h0.at(key)) energy_scale = std::max(energy_scale, std::fabs(x));
      const double momentum_scale = std::sqrt(2 * mass * energy_scale);
      double history_error = 0;
      for (const auto& key : kHistory) {
        if (!h0.count(key)) continue;
        const auto& a = h0.at(key);
        const auto& b = h.at(key);
        const double scale = key == "time"                   ? 1.0
                             : key.rfind("momentum", 0) == 0 ? momentum_scale
                                                             : energy_scale;
        for (size_t i = 0; i < a.size(); ++i)
          history_error = std::max(history_error, std::fabs(a[i] - b[i]) / scale);
      }
      // Particle fields, id sets and mass at every frame; the last one after 200 (500) steps.
      // The particles held by another rank in some frame than at the start: the run crossed
      // the cuts.
      Difference difference;
      const Frame first = read_frame(dir.path / out, 0, ranks);
      std::set<int> moved;
      for (long f : frame_ids) {
        const Frame fr = read_frame(dir.path / out, f, ranks);
        difference.add(read_frame(dir.path / "serial", f, 0), fr);
        for (const auto& [id, r] : fr.piece)
          if (first.piece.count(id) && first.piece.at(id) != r) moved.insert(id);
      }
      const double field_error = difference.relative();
      const bool ids_match = difference.ids_match;
      // Probes (disks: two particles, one node; the staged columns: particles at the base and
      // the toe): every step's row, each column within 1e-10
      // of its largest magnitude, as the frames' fields.
      double probe_error = 0;
      long probe_rows = 0;
      for (const char* probe : {"left_front", "right_front", "middle", "base", "base_2", "toe"}) {
        const fs::path csv = fs::path("probe_") += std::string(probe) + ".csv";
        if (!fs::exists(dir.path / "serial" / csv)) continue;
        const auto p0 = loam_test::read_csv_columns(dir.path / "serial" / csv);
        const auto p = loam_test::read_csv_columns(dir.path / out / csv);
        REQUIRE(p.at("step") == p0.at("step"));
        for (const auto& [key, a] : p0) {
          const auto& b = p.at(key);
          double scale = 0;
          for (double x : a) scale = std::max(scale, std::fabs(x));
          for (size_t i = 0; i < a.size(); ++i)
            probe_error = std::max(probe_error, std::fabs(a[i] - b[i]) / (scale > 0 ? scale : 1.0));
        }
        probe_rows += long(p0.at("step").size());
      }
      // summary.json: the whole model's counts and masses, written by the first rank.
      const auto summary = nlohmann::json::parse(loam_test::slurp(dir.path / out / "summary.json"));
      const auto summary0 =
          nlohmann::json::parse(loam_test::slurp(dir.path / "serial" / "summary.json"));
      CHECK(summary["particles"] == summary0["particles"]);
      CHECK(summary["ranks"] == ranks);
      for (const char* key : {"initial", "final", "created", "removed"})
        CHECK(std::fabs(summary["mass"][key].get<double>() - summary0["mass"][key].get<double>()) <=
              1e-12 * mass);
      // The reference's metrics (the columns: run-out, final height, largest speed), over
      // the ranks.
      for (const auto& [key, value] : summary0["verify"].items()) {
        if (!value.is_number()) continue;
        INFO("verify." << key);
        const double a = value.get<double>(), b = summary["verify"][key].get<double>();
        CHECK(std::fabs(a - b) <= 1e-10 * std::max(1.0, std::fabs(a)));
      }
      if (scene.name.find("column collapse") != std::string::npos)
        CHECK(summary0["verify"].contains("runout"));
      CHECK(std::fabs(summary["energy_final"]["kinetic"].get<double>() -
                      summary0["energy_final"]["kinetic"].get<double>()) <= 1e-12 * energy_scale);
      const long last = frame_ids.back();
      const bool same_bits = frames_identical(read_frame(dir.path / "serial", last, 0),
                                              read_frame(dir.path / out, last, ranks));
      std::printf(
          "mpi run, %-26s -np %d: history (momentum, energies) %.2e, particle fields %.2e over "
          "%zu frames, probes %.2e over %ld rows, ids %s, %zu of %zu particles changed rank%s\n",
          scene.name.c_str(), ranks, history_error, field_error, frame_ids.size(), probe_error,
          probe_rows, ids_match ? "match" : "DIFFER", moved.size(), first.count,
          same_bits ? ", bitwise the serial run" : "");
      CHECK(ids_match);
      CHECK(history_error <= 1e-12);
      CHECK(field_error <= 1e-10);
      CHECK(probe_error <= 1e-10);
      if (scene.name.find("disks") != std::string::npos) CHECK(probe_rows > 0);
      if (ranks == 1) CHECK(same_bits);
      if (ranks > 1 && scene.crosses) CHECK(!moved.empty());
      // Stages: the same statuses, steps and times.
      if (summary0.contains("stages")) {
        REQUIRE(summary["stages"].size() == summary0["stages"].size());
        for (size_t k = 0; k < summary0["stages"].size(); ++k) {
          const auto &s = summary["stages"][k], &s0 = summary0["stages"][k];
          std::printf("  stage %zu '%s': %s after %ld steps (serial: %s after %ld)\n", k,
                      s0["name"].get<std::string>().c_str(), s["status"].get<std::string>().c_str(),
                      s["steps"].get<long>(), s0["status"].get<std::string>().c_str(),
                      s0["steps"].get<long>());
          CHECK(s["status"] == s0["status"]);
          CHECK(s["steps"] == s0["steps"]);
        }
        CHECK(summary["particles_created"] == summary0["particles_created"]);
        CHECK(summary["particles_removed"] == summary0["particles_removed"]);
      }
    }
    // Repeated at 2 ranks: the same bits (the neighbour order is fixed). Once per shape function.
    if (scene.name.find("column") == std::string::npos) continue;
    const auto again = run_on(dir.path, "np2_again", 2);
    REQUIRE(again.exit_code == 0);
    CHECK(frames_identical(read_frame(dir.path / "np2", frame_ids.back(), 2),
                           read_frame(dir.path / "np2_again", frame_ids.back(), 2)));
  }
}

TEST_CASE("mpirun: a run resumed from its ranks' checkpoints is bitwise the uninterrupted one",
          "[mpi][mpi_run][checkpoint]") {
  // docs/parallel.md "Checkpoints": every rank writes checkpoint_<step>_rRRRR.h5 of the same
  // step (its own particles, partition and writer state; the run's scalars), and --resume
  // restarts each rank from its own file at the same rank count. A run copied at the end and
  // resumed from the checkpoint of a step between two frames must rewrite every file of the
  // uninterrupted run bit for bit: each rank's frame pieces, the XDMF index, history.csv and
  // summary.json's numbers. Resuming at another rank count, or a serial run's checkpoints under
  // mpirun, is refused with the reason.
  struct Case {
    std::string name, yaml;
    int ranks;
    long from;
  };
  const std::vector<Case> cases = {
      {"2D disks gimp, 2 ranks", disks(2, "gimp"), 2, 120},
      {"2D disks gimp, 4 ranks", disks(2, "gimp"), 4, 90},
      {"2D saturated disks gimp, 2 ranks",
       disks(2, "gimp",
             "{type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: 1.0e4, drag: "
             "{type: darcy, hydraulic_conductivity: 1.0e-3}}",
             "{end: 0.6, dt: 0.0015}"),
       2, 240}};
  const std::string ck = "--set 'output.checkpoint={every_steps: 30, keep: 100}'";
  for (const Case& c : cases) {
    INFO(c.name);
    TempDir dir("mpi_resume");
    fs::create_directories(dir.path);
    std::ofstream(dir.path / "run.yaml") << c.yaml;
    const auto a = run_on(dir.path, "a", c.ranks, ck);
    INFO(a.output);
    REQUIRE(a.exit_code == 0);
    char name[64];
    for (int r = 0; r < c.ranks; ++r) {
      std::snprintf(name, sizeof name, "checkpoint_%08ld_r%04d.h5", c.from, r);
      REQUIRE(fs::exists(dir.path / "a" / name));
    }
    fs::copy(dir.path / "a", dir.path / "b", fs::copy_options::recursive);
    fs::remove(dir.path / "b" / "summary.json");
    std::snprintf(name, sizeof name, "checkpoint_%08ld_r0000.h5", c.from);
    const auto b =
        run_on(dir.path, "b", c.ranks, ck + " --resume " + (dir.path / "b" / name).string());
    INFO(b.output);
    REQUIRE(b.exit_code == 0);
    long files = 0, frames = 0;
    for (const auto& e : fs::directory_iterator(dir.path / "a")) {
      const std::string n = e.path().filename().string();
      const std::string ext = e.path().extension().string();
      INFO(n);
      if (ext == ".csv" || ext == ".xdmf") {
        CHECK(loam_test::slurp(e.path()) == loam_test::slurp(dir.path / "b" / n));
        ++files;
      } else if (ext == ".h5" && n.rfind("particles_", 0) == 0) {
        for (const auto& field : dataset_names(e.path()))
          if (field != "id")
            CHECK(loam_test::read_frame_doubles(e.path(), field) ==
                  loam_test::read_frame_doubles(dir.path / "b" / n, field));
        CHECK(loam_test::read_frame_ids(e.path()) == loam_test::read_frame_ids(dir.path / "b" / n));
        ++frames;
      }
    }
    auto sa = nlohmann::json::parse(loam_test::slurp(dir.path / "a" / "summary.json"));
    auto sb = nlohmann::json::parse(loam_test::slurp(dir.path / "b" / "summary.json"));
    for (const char* k :
         {"wall_seconds", "particle_steps_per_second", "profile_seconds", "config_file"})
      sa.erase(k), sb.erase(k);
    CHECK(sa == sb);
    std::printf("%s: resumed from step %ld, %ld frame pieces and %ld index/CSV files compared\n",
                c.name.c_str(), c.from, frames, files);
    CHECK(frames >= 5 * c.ranks);
  }

  // The newest checkpoint of the directory at the same rank count resumes; another rank count,
  // and a serial run's checkpoints under mpirun, are refused with the rank count to use.
  TempDir dir("mpi_resume_refused");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml") << disks(2, "linear");
  REQUIRE(run_on(dir.path, "np2", 2, ck).exit_code == 0);
  const auto newest = run_on(dir.path, "np2", 2, ck + " --resume " + (dir.path / "np2").string());
  INFO(newest.output);
  CHECK(newest.exit_code == 0);
  const auto other = run_on(dir.path, "np2", 4, ck + " --resume " + (dir.path / "np2").string());
  std::printf("resumed at 4 ranks from 2: exit %d\n%s", other.exit_code, other.output.c_str());
  CHECK(other.exit_code == 2);
  CHECK(other.output.find("written by a run on 2 rank(s)") != std::string::npos);
  REQUIRE(run_on(dir.path, "serial", 0, ck).exit_code == 0);
  const auto serial =
      run_on(dir.path, "serial", 2, ck + " --resume " + (dir.path / "serial").string());
  std::printf("serial checkpoints resumed at 2 ranks: exit %d\n%s", serial.exit_code,
              serial.output.c_str());
  CHECK(serial.exit_code == 2);
  CHECK(serial.output.find("written by a run on 1 rank(s)") != std::string::npos);
}

TEST_CASE("mpirun: what does not run on ranks yet is refused with located errors, writing nothing",
          "[mpi][mpi_run][bad_config]") {
  // docs/parallel.md "What runs on ranks": a plugin that does not declare runs_on_ranks, and the
  // keys of features not split yet, are errors at their place in the file, every one at once,
  // exit 2, before any output; so is a grid too thin for the ranks.
  TempDir dir("mpi_refused_features");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.05}\n"
         "shape_function: cpdi\n"
         "scheme: {type: single_phase, update: musl}\n"
         "bodies:\n"
         "  - name: block\n"
         "    generator: {type: box, min: [0.2, 0.2], max: [0.6, 0.6]}\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "loads:\n"
         "  - {type: point, position: [0.4, 0.4], force: [1, 0]}\n"
         "boundaries:\n"
         "  - {type: fixed, min: [0, 0], max: [1, 0.1]}\n"
         "  - {type: absorbing, face: x+, density: 1000, p_wave_speed: 1.2, s_wave_speed: 0}\n"
         "time: {end: 0.1}\n"
         "probes:\n"
         "  - {name: corner, particle_near: [0.2, 0.2], fields: [velocity]}\n";
  check_refused(dir.path, 2,
                {"run.yaml:2:17: error: shape_function: 'cpdi' does not run under mpirun yet",
                 "run.yaml:9:5: error: loads.0: 'point' does not run under mpirun yet",
                 "run.yaml:11:5: error: boundaries.0: 'fixed' does not run under mpirun yet",
                 "run.yaml:12:5: error: boundaries.1: 'absorbing' does not run under mpirun yet"});

  // Four ranks on a grid of 3 cells along x: a gimp block needs 2 (its reach).
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [0], extent: [0.3], cell_size: 0.1}\nshape_function: gimp\n"
         "bodies:\n  - name: bar\n    generator: {type: box, min: [0], max: [0.3]}\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "time: {end: 0.1}\n";
  check_refused(dir.path, 4,
                {"run.yaml:1:7: error: grid: the grid has 3 cells along x for 4 ranks: a block "
                 "needs at least 2 cells"});
}

#endif  // LOAM_MPI_BUILD
