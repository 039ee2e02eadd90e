// Whole runs under mpirun (docs/parallel.md "Tests"): `mpirun -np N loam run` at 1, 2
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
#include <utility>
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

/// Set `set`'s piece of a frame: <set>_NNNNNN.h5 serially (rank < 0), <set>_NNNNNN_rRRRR.h5.
fs::path frame_file(const fs::path& out, long frame, int rank,
                    const std::string& set = "particles") {
  char name[64];
  if (rank < 0)
    std::snprintf(name, sizeof name, "_%06ld.h5", frame);
  else
    std::snprintf(name, sizeof name, "_%06ld_r%04d.h5", frame, rank);
  return out / (set + name);
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

/// Set `set`'s particles of a frame: the rank pieces under mpirun (a rank without particles of
/// the set writes none), the one file serially.
Frame read_frame(const fs::path& out, long frame, int ranks, const std::string& set = "particles") {
  Frame fr;
  for (int r = 0; r < std::max(ranks, 1); ++r) {
    const fs::path file = frame_file(out, frame, ranks > 0 ? r : -1, set);
    if (ranks > 0 && !fs::exists(file)) continue;
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
  /// `prefix` names the set in the fields' keys (the double-point scheme's solid and liquid).
  void add(const Frame& a, const Frame& b, const std::string& prefix = "") {
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
        auto& [diff, scale] = field[prefix + a.fields[f]];
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
  int crosses = 2;  // particles change rank from this rank count on (0: never)
  std::vector<std::string> sets = {"particles"};  // the scheme's particle sets
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

/// Two disks on a grid periodic along x (linear): each leaves through a side face and comes in
/// at the other while it crosses the cuts along y (the ranks keep x whole).
std::string periodic_disks() {
  return "grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.025}\nshape_function: linear\n"
         "scheme: {type: single_phase, update: musl}\n"
         "bodies:\n"
         "  - name: a\n    generator: {type: sphere, center: [0.8, 0.3], radius: 0.15}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "    velocity: [0.6, 0.4]\n"
         "  - name: b\n    generator: {type: sphere, center: [0.25, 0.75], radius: 0.15}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "    velocity: [-0.5, -0.3]\n"
         "boundaries:\n  - {type: periodic, axis: x}\n"
         "time: {end: 1.0, dt: 0.005}\n"
         "output: {every_steps: 50, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass]}\n"
         // The particle at a's front, through the face x = 1 and across the cut y = 0.5.
         "probes:\n  - {name: left_front, particle_near: [0.95, 0.3], fields: [position, "
         "velocity, stress]}\n";
}

/// A plate with a pressurised hole whose centre is where the cuts of 2 and 4 blocks meet: the
/// wall's samples go to particles of every rank, equally near ones (the lattice is symmetric
/// about the hole) by the serial tie rule. The blast_wave reference follows the wave at two
/// probes; the second one's point is equally near to particles on both sides of the cut.
std::string pressurised_hole() {
  return "grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.025}\nshape_function: gimp\n"
         "scheme: {type: single_phase, update: musl}\ngravity: [0, 0]\n"
         "bodies:\n"
         "  - name: plate\n    particles_per_cell: 2\n"
         "    generator: {type: difference, of: {type: box, min: [0.1, 0.1], max: [0.9, 0.9]}, "
         "minus: [{type: cylinder, center: [0.5, 0.5], radius: 0.15}]}\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "loads:\n  - {type: cavity_pressure, body: plate, cavity: {type: cylinder, center: "
         "[0.5, 0.5], radius: 0.15}, pressure: 50}\n"
         "verify: {type: blast_wave, body: plate, cavity: {type: cylinder, center: [0.5, 0.5], "
         "radius: 0.15}, probes: [{name: a, position: [0.75, 0.5]}, {name: b, position: [0.5, "
         "0.2]}]}\n"
         "time: {end: 1.0, dt: 0.005}\n"
         "output: {every_steps: 50, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass]}\n";
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
/// damping), measured by the reference `verify`.
std::string column(const std::string& shape,
                   const std::string& verify = "{type: granular_collapse}") {
  return column_setting(shape) +
         "bodies:\n  - name: sand\n    generator: {type: box, min: [0, 0], max: [0.27, 0.25]}\n" +
         kSand +
         "boundaries:\n  - {type: slip, face: x-}\n"
         "  - {type: friction, face: y-, coefficient: 0.5}\n  - {type: fixed, face: x+}\n"
         "damping: {type: local, alpha: 0.05}\n"
         "time: {end: 0.25, dt: 5.0e-4}\n"
         "output: {every_steps: 100, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass]}\n"
         "verify: " +
         verify + "\n";
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
         "         fields: [velocity, stress, mass, pore_pressure, water_velocity, porosity]}\n"
         "verify: {type: terzaghi, load: 1.0e4, consolidation_coefficient: 1.0194,\n"
         "         time_factors: [0.0005, 0.001, 0.002]}\n";
}

/// The double-point scheme's saturated disks: disks()'s grains (solid set) with water in their
/// pores (liquid set, soft, so that the fast wave allows a step of 1.5 ms), moving across the
/// cuts; probes on a grain, a water point and the middle node.
std::string double_point_disks(int dim, const std::string& shape) {
  std::string cfg = disks(dim, shape,
                          "{type: two_phase_double_point, porosity: 0.4, drag: {type: darcy, "
                          "hydraulic_conductivity: 1.0e-3}}",
                          "{end: 0.6, dt: 0.0015}");
  const std::string water =
      "    material: {type: newtonian_fluid, bulk_modulus: 1.0e4, viscosity: 1.0e-3, "
      "density: 1000}\n";
  auto insert_water = [&](const std::string& body) {
    // A liquid body at the same place and speed as `body`.
    const size_t at = cfg.find("  - name: " + body + "\n");
    const size_t gen = cfg.find("    generator:", at);
    const std::string generator = cfg.substr(gen, cfg.find('\n', gen) + 1 - gen);
    const size_t vel = cfg.find("    velocity:", at);
    const std::string velocity = cfg.substr(vel, cfg.find('\n', vel) + 1 - vel);
    const std::string liquid = "  - name: " + body + "_water\n    set: liquid\n" + generator +
                               "    particles_per_cell: 2\n" + water + velocity;
    const size_t end = cfg.find('\n', vel) + 1;
    cfg.insert(end, liquid);
    cfg.insert(at + ("  - name: " + body + "\n").size(), "    set: solid\n");
  };
  insert_water("left");
  insert_water("right");
  const std::string fields = "[velocity, stress, mass, pore_pressure, water_velocity]";
  cfg.replace(cfg.find(fields), fields.size(),
              "[velocity, stress, mass, pore_pressure, porosity, contact, free_surface]");
  const std::string probe = "fields: [velocity, stress]}";
  cfg.replace(cfg.find(probe), probe.size(), "set: liquid, fields: [velocity, stress]}");
  cfg.replace(cfg.find("fields: [mass, velocity]}"), 25,
              "fields: [mass, velocity, water_mass, water_velocity, porosity]}");
  return cfg;
}

/// Water running onto a block of dry soil (double point, CFL time step): the water on the left,
/// the soil on the right, so that at 2 ranks one rank starts with water only and the other with
/// soil only; the time step's fast wave of the soil with the water's bulk modulus is then a
/// reduction over the ranks (TwoPhaseDoublePoint::stable_dt). The water crosses the cut and
/// enters the soil's pores.
std::string dam_break_on_soil(const std::string& shape) {
  return "grid: {origin: [0, 0], extent: [1.0, 0.4], cell_size: 0.02}\nshape_function: " + shape +
         "\ngravity: [0, -9.81]\n"
         "scheme: {type: two_phase_double_point, porosity: 0.4, max_porosity: 0.5, drag: {type: "
         "darcy, hydraulic_conductivity: 1.0e-2}}\n"
         "bodies:\n"
         "  - name: soil\n    set: solid\n    generator: {type: box, min: [0.5, 0], max: [1.0, "
         "0.1]}\n    material: {type: mohr_coulomb, E: 1.0e6, nu: 0.3, density: 2650, c: 0, phi: "
         "30, psi: 0}\n"
         "  - name: water\n    set: liquid\n    generator: {type: box, min: [0, 0], max: [0.25, "
         "0.3]}\n    material: {type: newtonian_fluid, bulk_modulus: 1.0e6, viscosity: 1.0e-3, "
         "density: 1000}\n"
         "    stress: {type: linear_profile, value: [0, 0, 0, 0], gradient: [9810, 9810, 9810, 0], "
         "axis: 1, origin: 0.3}\n"
         "boundaries:\n  - {type: slip, face: x-}\n  - {type: fixed, face: y-}\n"
         "  - {type: slip, face: x+}\n"
         "time: {end: 0.25, cfl: 0.5}\n"
         "output: {every_time: 0.05, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass, pore_pressure, porosity, contact, free_surface]}\n";
}

/// Water created and removed while the run goes (double point): a saturated sand bed, a
/// `reservoir` on its left half whose level rises (new layers of water at the top, counted from
/// the water in its box over all ranks), an `inflow` jet falling on the right half, and a
/// `region` sink taking the water that the jet splashes to the right over the bed's surface
/// (and `open_faces` the splashes that leave the grid). At 2 ranks the
/// pool and the sink are on different ranks; at 4 the pool's top crosses the cut too.
std::string pool_jet_and_sink(const std::string& shape) {
  return "grid: {origin: [0, 0], extent: [1.0, 0.6], cell_size: 0.02}\nshape_function: " + shape +
         "\ngravity: [0, -9.81]\n"
         "scheme: {type: two_phase_double_point, porosity: 0.4, drag: {type: darcy, "
         "hydraulic_conductivity: 1.0e-2}}\n"
         "bodies:\n"
         "  - name: sand\n    set: solid\n    generator: &bed {type: box, min: [0, 0], max: [1.0, "
         "0.2]}\n    material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 2650}\n"
         "  - name: pore_water\n    set: liquid\n    generator: *bed\n    material: &water "
         "{type: newtonian_fluid, bulk_modulus: 1.0e6, viscosity: 1.0e-3, density: 1000}\n"
         "  - {name: pool, set: liquid, material: *water}\n"
         "  - {name: jet, set: liquid, material: *water}\n"
         "boundaries:\n  - {type: slip, face: x-}\n  - {type: fixed, face: y-}\n"
         "  - {type: slip, face: x+}\n"
         "sources:\n"
         "  - {type: reservoir, body: pool, min: [0, 0.2], max: [0.45, 0.4], refill: y+, level: "
         "0.3, level_rate: 0.5}\n"
         "  - {type: inflow, body: jet, min: [0.6, 0.5], max: [0.7, 0.54], velocity: [0, -3]}\n"
         "sinks:\n  - {type: region, set: liquid, min: [0.8, 0.21], max: [1.0, 0.45]}\n"
         "  - {type: open_faces, set: liquid}\n"
         "time: {end: 0.3, cfl: 0.5}\n"
         "output: {every_time: 0.05, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, mass, pore_pressure, porosity]}\n";
}

/// configs/terzaghi_double_point.yaml (solid and liquid points, a traction on the grains' top,
/// water free to leave at the top), 250 steps of its consolidation's start.
std::string terzaghi_double_point_1d() {
  return "grid: {origin: [0], extent: [1.0], cell_size: 0.025}\n"
         "scheme: {type: two_phase_double_point, porosity: 0.4,\n"
         "         drag: {type: darcy, hydraulic_conductivity: 1.0e-3}}\n"
         "bodies:\n  - name: column\n    set: solid\n    generator: {type: box, min: [0], max: "
         "[1.0]}\n    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1.0e7, nu: 0.0, density: 2650}\n"
         "  - name: water\n    set: liquid\n    generator: {type: box, min: [0], max: [1.0]}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: newtonian_fluid, bulk_modulus: 2.2e9, viscosity: 1.0e-3, density: "
         "1000}\n"
         "boundaries:\n  - {type: fixed, face: x-}\n"
         "loads:\n  - {type: traction, body: column, face: x+, traction: [-1.0e4]}\n"
         "time: {end: 2.0e-3, dt: 8.0e-6}\n"
         "output: {every_steps: 50, history_every: 1, history_digits: 17,\n"
         "         fields: [velocity, stress, mass, pore_pressure, porosity]}\n"
         "verify: {type: settlement, body: column, load: 1.0e4}\n";
}

/// configs/vibrating_bar.yaml for 10 s (its first mode's period is 20 s), verify: vibrating_bar
/// (modal sums over the ranks, the mode shape of the whole bar on every rank).
std::string vibrating_bar() {
  return "grid: {origin: [0], extent: [27], cell_size: 1.0}\n"
         "bodies:\n  - name: bar\n    generator: {type: box, min: [0], max: [25]}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 100, nu: 0, density: 1}\n"
         "    velocity: {type: sine, amplitude: [0.1], wavenumber: [0.06283185307179587]}\n"
         "boundaries:\n  - {type: fixed, face: x-}\n"
         "time: {end: 10, cfl: 0.1}\n"
         "output: {every_time: 2.0, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, displacement]}\n"
         "verify: {type: vibrating_bar, v0: 0.1}\n";
}

/// configs/elastic_column_2d.yaml undamped for 0.05 s (the column starts falling under its
/// weight), verify: elastic_column (integrals summed, the top particle over the ranks).
std::string elastic_column_2d() {
  return "grid: {origin: [0, 0], extent: [1.0, 10.5], cell_size: 0.25}\ngravity: [0, -9.81]\n"
         "bodies:\n  - name: column\n    generator: {type: box, min: [0, 0], max: [1.0, 10]}\n"
         "    particles_per_cell: 2\n"
         "    material: {type: linear_elastic, E: 1.0e9, nu: 0.3, density: 2000}\n"
         "boundaries:\n  - {type: fixed, face: y-}\n  - {type: slip, face: x-}\n"
         "  - {type: slip, face: x+}\n"
         "time: {end: 0.05, cfl: 0.5}\n"
         "output: {every_time: 0.01, history_every: 1, history_digits: 17, fields: [velocity, "
         "stress, displacement]}\n"
         "verify: {type: elastic_column}\n";
}

/// elastic_column_2d() with gimp on an absorbing base with its free-field reaction (a dashpot
/// per node, each rank's own reaction state), loaded on its top by a traction applied at the
/// particles' surface points (each rank's share completed over the ranks).
std::string elastic_column_loaded_2d() {
  std::string cfg = elastic_column_2d();
  auto replace = [&](const std::string& a, const std::string& b) {
    REQUIRE(cfg.find(a) != std::string::npos);
    cfg.replace(cfg.find(a), a.size(), b);
  };
  replace("  - {type: fixed, face: y-}\n",
          "  - {type: absorbing, face: y-, density: 2000, p_wave_speed: 820.4, s_wave_speed: "
          "438.5, free_field: true}\n");
  replace("gravity: [0, -9.81]\n", "gravity: [0, -9.81]\nshape_function: gimp\n");
  replace("time:",
          "loads:\n  - {type: traction, body: column, face: y+, traction: [0, -1.0e5], "
          "apply_at: surface}\ntime:");
  return cfg;
}

/// configs/seed003_water_jet_2d.yaml on 0.5 m cells for 0.5 s: the inflow (a jet across the cut
/// at x = 10 m), the open faces' sink, ergun drag, fluidisation, verify: scour_depth (the
/// strip's highest grain over the ranks).
std::string water_jet_2d() {
  std::string cfg =
      loam_test::slurp(fs::path(LOAM_SOURCE_DIR) / "configs" / "seed003_water_jet_2d.yaml");
  auto replace = [&](const std::string& a, const std::string& b) {
    REQUIRE(cfg.find(a) != std::string::npos);
    cfg.replace(cfg.find(a), a.size(), b);
  };
  replace("cell_size: 0.125", "cell_size: 0.5");
  replace("time: {end: 1.0, cfl: 0.3}", "time: {end: 0.5, cfl: 0.3}");
  replace("output: {every_time: 0.1,",
          "output: {every_time: 0.1, history_every: 1, history_digits: 17,");
  return cfg;
}

/// configs/seed000_piping.yaml on 0.25 m cells for 0.1 s, 464 steps (as its quick test: the
/// grains' hold on the pile's tip line): boxes of nodes (the pile), the rising reservoir, the
/// region sink, verify: sheet_pile_seepage (its cell sums merged over the ranks). The seepage
/// moves its points far less than a cell: none changes rank. Over 0.5 s (about 2300 steps) the
/// stiff water (K_w = 200 MPa) had grown the round-off of the ranks' sums to 1.1e-10 and
/// 1.45e-10 of a field at 2 and 4 ranks (2.5e-11 after 0.1 s).
std::string piping() {
  std::string cfg = loam_test::slurp(fs::path(LOAM_SOURCE_DIR) / "configs" / "seed000_piping.yaml");
  auto replace = [&](const std::string& a, const std::string& b) {
    REQUIRE(cfg.find(a) != std::string::npos);
    cfg.replace(cfg.find(a), a.size(), b);
  };
  replace("cell_size: 0.125", "cell_size: 0.25");
  replace("min: [4.125, 3], max: [4.125, 10]", "min: [4, 3], max: [4.25, 3]");
  replace("time: {end: 50.0}", "time: {end: 0.1}");
  replace("output: {every_time: 0.5,",
          "output: {every_time: 0.02, history_every: 1, history_digits: 17,");
  return cfg;
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
const std::vector<std::string> kHistory = {
    "time",       "kinetic_energy", "strain_energy", "gravity_energy", "momentum_x",
    "momentum_y", "momentum_z",     "particles",     "mass_created",   "mass_removed"};

/// The whole-run scenes: every shape function in 1D-3D, the update orders and transfers, F-bar,
/// both two-phase schemes, stages, references, sources and sinks.
std::vector<Scene> whole_run_scenes() {
  std::vector<Scene> scenes;
  for (const std::string shape : {"linear", "gimp", "bspline2"}) {
    for (int dim = 1; dim <= 3; ++dim)
      scenes.push_back({std::to_string(dim) + "D disks " + shape, disks(dim, shape)});
    scenes.push_back({"2D column collapse " + shape,
                      shape == "bspline2"
                          ? column(shape,
                                   "{type: slope_failure, toe: 0.27, moved_displacement: 0.01, "
                                   "every: 0.05, surface_at: [0.05]}")
                          : column(shape)});
  }
  // The other update orders and the affine transfers (their nodal sums are completed after
  // each scatter as MUSL's).
  // CPDI: its domains stay within a cell of their particles (the ghost layer it runs with).
  scenes.push_back({"2D disks cpdi", disks(2, "cpdi")});
  scenes.push_back({"2D disks periodic along x", periodic_disks()});
  scenes.push_back({"2D pressurised hole (cavity_pressure, blast_wave)", pressurised_hole(), 0});
  scenes.push_back({"2D disks gimp usf", disks(2, "gimp", "{type: single_phase, update: usf}")});
  scenes.push_back({"2D disks gimp usl", disks(2, "gimp", "{type: single_phase, update: usl}")});
  scenes.push_back({"2D disks bspline2 apic",
                    disks(2, "bspline2", "{type: single_phase, update: musl, transfer: apic}")});
  scenes.push_back({"2D disks gimp tpic",
                    disks(2, "gimp", "{type: single_phase, update: musl, transfer: tpic}")});
  // F-bar: its nodal averages are completed over the ranks after each of its scatters.
  scenes.push_back({"2D disks gimp fbar",
                    disks(2, "gimp", "{type: single_phase, update: musl, volumetric: fbar}")});
  scenes.push_back({"3D disks bspline2 fbar",
                    disks(3, "bspline2", "{type: single_phase, update: musl, volumetric: fbar}")});
  scenes.push_back({"3D disks linear usf apic",
                    disks(3, "linear", "{type: single_phase, update: usf, transfer: apic}")});
  // Two-phase (single point): a Terzaghi column under a traction, and saturated disks (a soft
  // pore fluid, so that they move across the cuts in 400 steps).
  scenes.push_back({"1D Terzaghi two-phase", terzaghi_1d(), 0});
  // Stages: configs/construction_column_1d.yaml without its damping (local damping's sign(v)
  // turns round-off at nodes near rest into differences of 1e-8, so a column damped to rest
  // matches the serial run only that far) and with stages of 0.06 s: a column under gravity, a
  // second body activated on it and removed again, each stage `until: static` (motion_speed
  // over the ranks is checked; the column keeps vibrating, so each ends at max_time), probes at
  // the base; and a 2D column whose upper body joins in a second stage with its own friction
  // floor.
  scenes.push_back({"1D construction column stages", staged_column_1d(), 0});
  scenes.push_back({"2D column stages gimp", staged_column("gimp")});
  scenes.push_back(
      {"2D saturated disks gimp",
       disks(2, "gimp",
             "{type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: 1.0e4, drag: "
             "{type: darcy, hydraulic_conductivity: 1.0e-3}}",
             "{end: 0.6, dt: 0.0015}")});
  // Two-phase (double point): solid and liquid points, both sets migrating, the nodal records
  // and re-map of both phases and the cells' solid volumes and liquid sums completed.
  scenes.push_back(
      {"1D Terzaghi double point", terzaghi_double_point_1d(), 0, {"solid", "liquid"}});
  for (const std::string shape : {"gimp", "bspline2"})
    scenes.push_back({"2D saturated disks double point " + shape,
                      double_point_disks(2, shape),
                      2,
                      {"solid", "liquid"}});
  scenes.push_back({"3D saturated disks double point gimp",
                    double_point_disks(3, "gimp"),
                    2,
                    {"solid", "liquid"}});
  scenes.push_back(
      {"2D water onto soil double point", dam_break_on_soil("gimp"), 2, {"solid", "liquid"}});
  // The references (verify:) with their reductions over the ranks; the two Terzaghi columns
  // above carry terzaghi and settlement, the column collapses granular_collapse, the bspline2
  // one slope_failure.
  scenes.push_back({"1D vibrating bar", vibrating_bar(), 0});
  scenes.push_back({"2D elastic column", elastic_column_2d(), 0});
  scenes.push_back({"2D column absorbing, surface load", elastic_column_loaded_2d(), 0});
  // The jet falls along the cut between 2 blocks (x = 10 m) and splashes away from it: its
  // points cross the cut at 4 ranks (y = 5 m).
  scenes.push_back({"2D water jet double point", water_jet_2d(), 4, {"solid", "liquid"}});
  scenes.push_back({"2D piping double point", piping(), 0, {"solid", "liquid"}});
  // Sources and sinks: every rank creates the same layers and keeps its own cells' points, with
  // the serial ids; each removes its own.
  scenes.push_back(
      {"2D pool, jet and sink double point", pool_jet_and_sink("gimp"), 2, {"solid", "liquid"}});
  return scenes;
}

/// A scene's serial run in dir/serial: its history, frame numbers, mass and summary, and the
/// largest energy of the run (the scale of the energies' differences).
struct SerialRun {
  fs::path dir;
  std::map<std::string, std::vector<double>> history;
  std::vector<long> frames;
  double mass = 0, energy_scale = 0;
  nlohmann::json summary;
};
SerialRun run_serially(const Scene& scene, const fs::path& dir) {
  const auto r = run_on(dir, "serial", 0);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  SerialRun s;
  s.dir = dir / "serial";
  s.history = loam_test::read_csv_columns(s.dir / "history.csv");
  for (long f = 0; fs::exists(frame_file(s.dir, f, -1, scene.sets[0])); ++f) s.frames.push_back(f);
  REQUIRE(s.frames.size() >= 5);
  s.summary = nlohmann::json::parse(loam_test::slurp(s.dir / "summary.json"));
  for (const auto& set : scene.sets) s.mass += s.summary["sets"][set]["mass"].get<double>();
  for (const char* key : {"kinetic_energy", "strain_energy", "gravity_energy"})
    for (double x : s.history.at(key)) s.energy_scale = std::max(s.energy_scale, std::fabs(x));
  return s;
}

/// Momentum and energies at every step against the serial run's: energies relative to the
/// largest energy of the run, momentum to sqrt(2 M E_kin) (the momentum of the whole mass at
/// the rms speed), the particle count exactly (a difference of 1 exceeds the limit).
double history_error(const SerialRun& serial, const fs::path& out) {
  const auto& h0 = serial.history;
  const auto h = loam_test::read_csv_columns(out / "history.csv");
  REQUIRE(h.at("step") == h0.at("step"));
  const double momentum_scale = std::sqrt(2 * serial.mass * serial.energy_scale);
  double error = 0;
  for (const auto& key : kHistory) {
    if (!h0.count(key)) continue;
    const auto& a = h0.at(key);
    const auto& b = h.at(key);
    const double scale = key == "time" || key == "particles" ? 1.0
                         : key.rfind("mass_", 0) == 0        ? serial.mass
                         : key.rfind("momentum", 0) == 0     ? momentum_scale
                                                             : serial.energy_scale;
    for (size_t i = 0; i < a.size(); ++i) error = std::max(error, std::fabs(a[i] - b[i]) / scale);
  }
  return error;
}

/// Particle fields, id sets and mass at every frame against the serial run's, and the
/// particles held by another rank in some frame than at the start (the run crossed the cuts).
struct FrameComparison {
  double error = 0;
  bool ids_match = true;
  size_t moved = 0, particles = 0;
};
FrameComparison compare_frames(const Scene& scene, const SerialRun& serial, const fs::path& out,
                               int ranks) {
  Difference difference;
  std::set<int> moved;
  FrameComparison c;
  for (const auto& set : scene.sets) {
    std::map<int, int> last;  // id -> the rank that held it in the last frame it was in
    for (long f : serial.frames) {
      const Frame fr = read_frame(out, f, ranks, set);
      if (f == serial.frames.front()) c.particles += fr.count;
      difference.add(read_frame(serial.dir, f, 0, set), fr, set + ".");
      for (const auto& [id, r] : fr.piece) {
        if (last.count(id) && last.at(id) != r) moved.insert(id);
        last[id] = r;
      }
    }
  }
  c.error = difference.relative();
  c.ids_match = difference.ids_match;
  c.moved = moved.size();
  return c;
}

/// Probes (disks: two particles, one node; the staged columns: particles at the base and the
/// toe): every step's row, each column relative to its largest magnitude; and the rows compared.
std::pair<double, long> probe_error(const SerialRun& serial, const fs::path& out) {
  double error = 0;
  long rows = 0;
  for (const char* probe : {"left_front", "right_front", "middle", "base", "base_2", "toe"}) {
    const fs::path csv = fs::path("probe_") += std::string(probe) + ".csv";
    if (!fs::exists(serial.dir / csv)) continue;
    const auto p0 = loam_test::read_csv_columns(serial.dir / csv);
    const auto p = loam_test::read_csv_columns(out / csv);
    REQUIRE(p.at("step") == p0.at("step"));
    for (const auto& [key, a] : p0) {
      const auto& b = p.at(key);
      double scale = 0;
      for (double x : a) scale = std::max(scale, std::fabs(x));
      for (size_t i = 0; i < a.size(); ++i)
        error = std::max(error, std::fabs(a[i] - b[i]) / (scale > 0 ? scale : 1.0));
    }
    rows += long(p0.at("step").size());
  }
  return {error, rows};
}

/// summary.json on the ranks (written by the first rank) against the serial one: the whole
/// model's counts and masses, the reference's metrics over the ranks, the final kinetic energy,
/// each stage's status and steps, and the particles sources and sinks made and took.
void check_summary(const Scene& scene, const SerialRun& serial, const fs::path& out, int ranks) {
  const auto summary = nlohmann::json::parse(loam_test::slurp(out / "summary.json"));
  const auto& summary0 = serial.summary;
  CHECK(summary["particles"] == summary0["particles"]);
  CHECK(summary["ranks"] == ranks);
  for (const char* key : {"initial", "final", "created", "removed"})
    CHECK(std::fabs(summary["mass"][key].get<double>() - summary0["mass"][key].get<double>()) <=
          1e-12 * serial.mass);
  for (const auto& [key, value] : summary0["verify"].items()) {
    if (!value.is_number()) continue;
    INFO("verify." << key);
    const double a = value.get<double>(), b = summary["verify"][key].get<double>();
    CHECK(std::fabs(a - b) <= 1e-10 * std::max(1.0, std::fabs(a)));
  }
  if (scene.name.find("column collapse") != std::string::npos)
    CHECK(summary0["verify"].contains("runout"));
  CHECK(std::fabs(summary["energy_final"]["kinetic"].get<double>() -
                  summary0["energy_final"]["kinetic"].get<double>()) <=
        1e-12 * serial.energy_scale);
  if (summary0.contains("stages")) {
    REQUIRE(summary["stages"].size() == summary0["stages"].size());
    for (size_t k = 0; k < summary0["stages"].size(); ++k) {
      const auto &st = summary["stages"][k], &st0 = summary0["stages"][k];
      std::printf("  stage %zu '%s': %s after %ld steps (serial: %s after %ld)\n", k,
                  st0["name"].get<std::string>().c_str(), st["status"].get<std::string>().c_str(),
                  st["steps"].get<long>(), st0["status"].get<std::string>().c_str(),
                  st0["steps"].get<long>());
      CHECK(st["status"] == st0["status"]);
      CHECK(st["steps"] == st0["steps"]);
    }
  }
  CHECK(summary["particles_created"] == summary0["particles_created"]);
  CHECK(summary["particles_removed"] == summary0["particles_removed"]);
  if (scene.name.find("sink") != std::string::npos) {
    std::printf("  created %s, removed %s particles\n", summary["particles_created"].dump().c_str(),
                summary["particles_removed"].dump().c_str());
    CHECK(summary0["particles_created"].get<long>() > 0);
    CHECK(summary0["particles_removed"].get<long>() > 0);
  }
}

/// The scene under mpirun -np `ranks` into dir/np<ranks> against its serial run: history
/// within 1e-12, fields and probes within 1e-10, the same ids, -np 1 bitwise, the cuts crossed
/// where the scene says so, and the summary (check_summary).
void check_run_on_ranks(const Scene& scene, const SerialRun& serial, const fs::path& dir,
                        int ranks) {
  const std::string name = "np" + std::to_string(ranks);
  const auto r = run_on(dir, name, ranks);
  INFO(r.output);
  REQUIRE(r.exit_code == 0);
  const fs::path out = dir / name;
  const double history = history_error(serial, out);
  const FrameComparison frames = compare_frames(scene, serial, out, ranks);
  const auto [probes, probe_rows] = probe_error(serial, out);
  check_summary(scene, serial, out, ranks);
  const long last = serial.frames.back();
  bool same_bits = true;
  for (const auto& set : scene.sets)
    same_bits = same_bits && frames_identical(read_frame(serial.dir, last, 0, set),
                                              read_frame(out, last, ranks, set));
  std::printf(
      "mpi run, %-26s -np %d: history (momentum, energies) %.2e, particle fields %.2e over "
      "%zu frames, probes %.2e over %ld rows, ids %s, %zu particles changed rank (%zu at the "
      "start)%s\n",
      scene.name.c_str(), ranks, history, frames.error, serial.frames.size(), probes, probe_rows,
      frames.ids_match ? "match" : "DIFFER", frames.moved, frames.particles,
      same_bits ? ", bitwise the serial run" : "");
  CHECK(frames.ids_match);
  CHECK(history <= 1e-12);
  CHECK(frames.error <= 1e-10);
  CHECK(probes <= 1e-10);
  if (scene.name.find("disks") != std::string::npos) CHECK(probe_rows > 0);
  if (ranks == 1) CHECK(same_bits);
  if (scene.crosses > 0 && ranks >= scene.crosses) CHECK(frames.moved > 0);
}

/// Each scene run serially and under mpirun at each of `rank_counts` (check_run_on_ranks), and
/// the columns repeated at the last rank count: the same bits (the neighbour order is fixed),
/// once per shape function. The ranks add the ghost layer's shares in another order than the
/// serial scatter, so they agree with it to round-off only.
void check_whole_runs(const std::vector<int>& rank_counts) {
  for (const Scene& scene : whole_run_scenes()) {
    INFO(scene.name);
    TempDir dir("mpi_run");
    fs::create_directories(dir.path);
    std::ofstream(dir.path / "run.yaml") << scene.yaml;
    const SerialRun serial = run_serially(scene, dir.path);
    for (int ranks : rank_counts) check_run_on_ranks(scene, serial, dir.path, ranks);
    if (scene.name.find("column") == std::string::npos) continue;
    const int ranks = rank_counts.back();
    const fs::path out = dir.path / ("np" + std::to_string(ranks));
    const auto again = run_on(dir.path, "again", ranks);
    REQUIRE(again.exit_code == 0);
    const long last = serial.frames.back();
    for (const auto& set : scene.sets)
      CHECK(frames_identical(read_frame(out, last, ranks, set),
                             read_frame(dir.path / "again", last, ranks, set)));
  }
}

}  // namespace

TEST_CASE("mpirun -np 1 and 4: whole runs match the serial run, every shape function, 1D-3D",
          "[mpi][mpi_run]") {
  // 4 ranks give every rank but the first and last two neighbours.
  check_whole_runs({1, 4});
}

TEST_CASE("mpirun -np 2: whole runs match the serial run, every shape function, 1D-3D",
          "[mpi][mpi_run][full]") {
  check_whole_runs({2});
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

TEST_CASE("mpirun: the grid output, each rank's own nodes, is the serial run's grid",
          "[mpi][mpi_run][grid_output]") {
  // docs/parallel.md "Output": with writer.grid each rank writes the nodes it owns into its
  // frame piece, so that over the ranks every node appears once; its nodal fields (mass,
  // velocity, acceleration) match the serial run's within 1e-10 of each field's largest
  // magnitude over the run (the ghost shares are summed in another order; before the disks
  // meet, the accelerations are round-off). The index's grid frames are spatial collections of
  // the pieces.
  TempDir dir("mpi_grid_output");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml") << disks(2, "gimp");
  const std::string grid = "--set 'output.writer={type: xdmf, grid: true}'";
  const auto serial = run_on(dir.path, "serial", 0, grid);
  INFO(serial.output);
  REQUIRE(serial.exit_code == 0);
  using Key = std::array<double, 3>;
  const std::vector<std::string> fields = {"grid_mass", "grid_velocity", "grid_acceleration"};
  std::map<std::string, double> scale;
  for (long f = 0; fs::exists(frame_file(dir.path / "serial", f, -1)); ++f)
    for (const auto& field : fields)
      for (double x : loam_test::read_frame_doubles(frame_file(dir.path / "serial", f, -1), field))
        scale[field] = std::max(scale[field], std::fabs(x));
  for (int ranks : {2, 4}) {
    const std::string out = "np" + std::to_string(ranks);
    const auto r = run_on(dir.path, out, ranks, grid);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const std::string index = loam_test::slurp(dir.path / out / "particles.xdmf");
    CHECK(index.find("<Grid Name=\"grid_r0001\"") != std::string::npos);
    double worst = 0;
    long frames = 0;
    for (long f = 0; fs::exists(frame_file(dir.path / "serial", f, -1)); ++f, ++frames) {
      const fs::path sf = frame_file(dir.path / "serial", f, -1);
      const auto spos = loam_test::read_frame_doubles(sf, "grid_position");
      std::map<Key, size_t> serial_node;
      for (size_t n = 0; n * 3 < spos.size(); ++n)
        serial_node[{spos[3 * n], spos[3 * n + 1], spos[3 * n + 2]}] = n;
      REQUIRE(serial_node.size() * 3 == spos.size());
      std::set<Key> seen;
      for (const auto& field : fields) {
        const auto sv = loam_test::read_frame_doubles(sf, field);
        const size_t width = sv.size() / serial_node.size();
        double diff = 0;
        for (int k = 0; k < ranks; ++k) {
          const fs::path pf = frame_file(dir.path / out, f, k);
          const auto pos = loam_test::read_frame_doubles(pf, "grid_position");
          const auto v = loam_test::read_frame_doubles(pf, field);
          REQUIRE(v.size() / width == pos.size() / 3);
          for (size_t n = 0; n * 3 < pos.size(); ++n) {
            const Key key{pos[3 * n], pos[3 * n + 1], pos[3 * n + 2]};
            REQUIRE(serial_node.count(key) == 1);
            if (field == "grid_mass") CHECK(seen.insert(key).second);  // once
            for (size_t c = 0; c < width; ++c)
              diff = std::max(diff, std::fabs(v[n * width + c] - sv[serial_node[key] * width + c]));
          }
        }
        REQUIRE(scale[field] > 0);
        const double rel = diff / scale[field];
        worst = std::max(worst, rel);
        INFO("frame " << f << " " << field << ": " << rel);
        CHECK(rel <= 1e-10);
      }
      CHECK(seen.size() == serial_node.size());  // every node written by one rank
    }
    std::printf(
        "grid output at %d ranks: %ld frames, every node once, fields within %.2e of "
        "serial (tolerance 1e-10)\n",
        ranks, frames, worst);
    CHECK(frames >= 5);
  }
}

TEST_CASE("loam run --profile: seconds per phase, and every rank's under mpirun",
          "[mpi][mpi_run][profile]") {
  // docs/runs.md, Commands: summary.json's profile_seconds times the step's phases; under mpirun
  // profile_seconds_by_rank holds each rank's, the halo exchange and the migration among them.
  TempDir dir("mpi_profile");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml") << disks(2, "linear");
  REQUIRE(run_on(dir.path, "serial", 0, "--profile").exit_code == 0);
  const auto serial = nlohmann::json::parse(loam_test::slurp(dir.path / "serial" / "summary.json"));
  CHECK(serial["profile_seconds"]["p2g"].get<double>() > 0);
  CHECK_FALSE(serial.contains("profile_seconds_by_rank"));
  const auto two = run_on(dir.path, "np2", 2, "--profile");
  INFO(two.output);
  REQUIRE(two.exit_code == 0);
  const auto s = nlohmann::json::parse(loam_test::slurp(dir.path / "np2" / "summary.json"));
  REQUIRE(s["profile_seconds_by_rank"].size() == 2);
  for (const auto& r : s["profile_seconds_by_rank"]) {
    std::printf("rank profile: %s\n", r.dump().c_str());
    for (const char* phase : {"p2g", "halo", "migration", "g2p_gradient_stress"})
      CHECK(r.at(phase).get<double>() > 0);
  }
  CHECK(s["profile_seconds"] == s["profile_seconds_by_rank"][0]);
}

TEST_CASE("mpirun: strength reduction on ranks finds the serial factor of safety",
          "[mpi][mpi_run][strength_reduction]") {
  // docs/strength_reduction.md on ranks (docs/parallel.md): a vertical cut 0.4 m high in a
  // c-phi soil (c = 2 kPa, phi = 30 deg; Terzaghi's critical height 4 c / gamma tan(45 + phi/2)
  // = 0.71 m), brought to rest by two stages (elastic, then Mohr-Coulomb; local damping), then
  // bisected between F = 1.2 and 2.4 to 0.05. The trials' largest displacement and motion speed
  // are maxima over the ranks, the stop on a signal agreed by all. Local damping's sign(v) makes
  // a state damped to rest differ from the serial one beyond round-off (docs/parallel.md
  // "Stages"), so the ranks must give the same trial outcomes and factor of safety; the steps
  // each takes are printed.
  TempDir dir("mpi_srf");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [0, 0], extent: [1.0, 0.5], cell_size: 0.05}\n"
         "gravity: [0, -9.81]\n"
         "bodies:\n  - name: soil\n    generator: {type: box, min: [0, 0], max: [0.5, 0.4]}\n"
         "    material: &soil {type: mohr_coulomb, E: 1.0e6, nu: 0.3, density: 2000, c: 2000, "
         "phi: 30, psi: 0}\n"
         "boundaries:\n  - {type: fixed, face: y-}\n  - {type: slip, face: x-}\n"
         "damping: {type: local, alpha: 0.7}\n"
         "output: {every_time: 1.0, fields: [velocity, stress, displacement]}\n"
         "stages:\n"
         "  - name: elastic\n    until: static\n    max_time: 2\n"
         "    materials: [{body: soil, material: {type: linear_elastic, E: 1.0e6, nu: 0.3, "
         "density: 2000}}]\n"
         "  - {name: mohr_coulomb, until: static, max_time: 2, materials: [{body: soil, "
         "material: *soil}]}\n"
         "strength_reduction: {factors: [1.2, 2.4], tolerance: 0.05, max_time: 8, "
         "failure_displacement: 0.02}\n";
  auto srf_of = [&](const std::string& out) {
    return nlohmann::json::parse(
        loam_test::slurp(dir.path / out / "summary.json"))["strength_reduction"];
  };
  const auto serial = run_on(dir.path, "serial", 0);
  INFO(serial.output);
  REQUIRE(serial.exit_code == 0);
  const auto s0 = srf_of("serial");
  REQUIRE(s0["status"] == "converged");
  for (int ranks : {2, 4}) {
    const std::string out = "np" + std::to_string(ranks);
    const auto r = run_on(dir.path, out, ranks);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const auto s = srf_of(out);
    std::printf("strength reduction, -np %d: F = %s (serial %s), %zu trials:", ranks,
                s["factor_of_safety"].dump().c_str(), s0["factor_of_safety"].dump().c_str(),
                s["trials"].size());
    for (size_t k = 0; k < s["trials"].size() && k < s0["trials"].size(); ++k)
      std::printf(
          " F %.4g %s in %ld steps (serial %s in %ld);", s["trials"][k]["factor"].get<double>(),
          s["trials"][k]["status"].get<std::string>().c_str(), s["trials"][k]["steps"].get<long>(),
          s0["trials"][k]["status"].get<std::string>().c_str(),
          s0["trials"][k]["steps"].get<long>());
    std::printf("\n");
    // Every trial decides within max_time (8 s; F = 2.175 passes 0.02 m after 4.1 s serially).
    // A trial near the factor ends close to failure_displacement, and the ranks' summation
    // order can move it across (docs/strength_reduction.md, "A verdict near the factor"):
    // outcomes may differ only for a trial that ended within 20 % of failure_displacement in
    // one of the two runs; the factor must then stay within one bisection step.
    CHECK(s["status"] == s0["status"]);
    REQUIRE(s["trials"].size() == s0["trials"].size());
    const double failure_displacement = 0.02;
    auto near_failure = [&](const nlohmann::json& t) {
      return t["max_displacement"].get<double>() > 0.8 * failure_displacement;
    };
    bool same = true;
    for (size_t k = 0; k < s0["trials"].size(); ++k) {
      const auto &a = s["trials"][k], &b = s0["trials"][k];
      if (a["factor"] != b["factor"]) break;  // the bisection parted after a late rest
      if (a["status"] == b["status"]) continue;
      same = false;
      INFO("trial F = " << a["factor"] << ": " << a.dump() << " against " << b.dump());
      CHECK((near_failure(a) || near_failure(b)));
    }
    if (same) CHECK(s["factor_of_safety"] == s0["factor_of_safety"]);
    CHECK(std::fabs(s["factor_of_safety"].get<double>() - s0["factor_of_safety"].get<double>()) <=
          s0["tolerance"].get<double>() * (1 + 1e-9));
    // The failure mechanism's frame (serially particles_000003_strength_reduction.h5): the
    // first rank's piece (the first block holds the cut's foot).
    CHECK(fs::exists(dir.path / out / "particles_000003_strength_reduction_r0000.h5"));
  }
}

TEST_CASE("mpirun: a fixed base's reaction is the serial one and the column's weight",
          "[mpi][mpi_run][reactions]") {
  // framework/reactions.hpp on ranks: each rank sums the nodes it owns, the step's values are
  // summed over the ranks. A 1 x 4 m elastic column (rho 2000, geostatic start, fixed base,
  // slip sides, local damping) cut in 2 and 4 blocks: every history row's base reaction within
  // 1e-9 of the serial run's (round-off of the sums' order), and its mean over the run within
  // 0.1 % of the weight W = rho g H = 78 480 N/m (statics).
  TempDir dir("mpi_reactions");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [0, 0], extent: [1.0, 4.5], cell_size: 0.125}\n"
         "gravity: [0, -9.81]\n"
         "bodies:\n  - name: column\n    generator: {type: box, min: [0, 0], max: [1.0, 4]}\n"
         "    material: {type: linear_elastic, E: 1.0e8, nu: 0.3, density: 2000}\n"
         "    stress: {type: linear_profile, value: [0, 0, 0, 0], gradient: [8408.571, 19620, "
         "8408.571, 0], axis: 1, origin: 4}\n"
         "boundaries:\n  - {type: fixed, face: y-, name: base}\n  - {type: slip, face: x-}\n"
         "  - {type: slip, face: x+}\n"
         "damping: {type: local, alpha: 0.3}\n"
         "time: {end: 0.05}\n"
         "output: {every_time: 1.0, history_every: 1, history_digits: 17}\n";
  const auto serial = run_on(dir.path, "serial", 0);
  INFO(serial.output);
  REQUIRE(serial.exit_code == 0);
  const auto y0 =
      loam_test::read_csv_columns(dir.path / "serial" / "history.csv")["reaction_base_y"];
  REQUIRE(y0.size() > 10);
  const double W = 2000 * 9.81 * 4;
  for (int ranks : {2, 4}) {
    const std::string out = "np" + std::to_string(ranks);
    const auto r = run_on(dir.path, out, ranks);
    INFO(r.output);
    REQUIRE(r.exit_code == 0);
    const auto y = loam_test::read_csv_columns(dir.path / out / "history.csv")["reaction_base_y"];
    REQUIRE(y.size() == y0.size());
    double worst = 0, mean = 0;
    for (size_t k = 0; k < y.size(); ++k) worst = std::max(worst, std::fabs(y[k] - y0[k]) / W);
    for (size_t k = 1; k < y.size(); ++k) mean += y[k] / double(y.size() - 1);
    std::printf(
        "reaction on %d ranks: largest difference from serial %.2e W, mean %.2f N/m "
        "(W %.0f, %+.4f %%)\n",
        ranks, worst, mean, W, 100 * (mean / W - 1));
    CHECK(worst <= 1e-9);
    CHECK(std::fabs(mean / W - 1) <= 1e-3);
  }
}

TEST_CASE("mpirun: contact and rigid bodies across the cut follow the serial run",
          "[mpi][mpi_run][contact]") {
  // framework/contact_fields.hpp and framework/rigid_fields.hpp on ranks (docs/parallel.md):
  // the fields' sums are completed like the shared record's, a rigid body's sums over its
  // particles and owned nodes are summed over the ranks and its held rows gathered. Three
  // scenes whose bodies cross the cut between the blocks (x = 0.5 m at 2 ranks): a free rigid
  // block sliding over an elastic slab on a fixed base (friction 0.3), two elastic blocks that
  // collide and part, and a footing bonded to the soil (a rigid_body not under contact). Every
  // history column at every step within 1e-9 of its largest serial magnitude (the order of the
  // sums over the ranks differs: round-off), at 2 and 4 ranks; the momentum of the collision is
  // kept to round-off on ranks too.
  const std::string slab =
      "grid: {origin: [0, 0], extent: [1.0, 0.6], cell_size: 0.05}\n"
      "gravity: [0, -9.81]\n"
      "bodies:\n"
      "  - {name: slab, generator: {type: box, min: [0, 0], max: [1.0, 0.1]},\n"
      "     material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}}\n"
      "  - {name: block, generator: {type: box, min: [0.3, 0.12], max: [0.5, 0.27]},\n"
      "     material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000},\n"
      "     velocity: [1.0, 0]}\n"
      "boundaries:\n  - {type: fixed, face: y-, name: base}\n"
      "  - {type: rigid_body, body: block, motion: free, name: block}\n"
      "contact: {type: friction, coefficient: 0.3}\n"
      "time: {end: 0.4}\n"
      "output: {every_time: 1.0, history_every: 1, history_digits: 17, energy_balance: true}\n";
  const std::string collision =
      "grid: {origin: [0, 0], extent: [1.0, 0.6], cell_size: 0.025}\n"
      "shape_function: gimp\n"
      "bodies:\n"
      "  - {name: left, generator: {type: box, min: [0.2, 0.2], max: [0.4, 0.4]},\n"
      "     material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000},\n"
      "     velocity: [1.0, 0.2]}\n"
      "  - {name: right, generator: {type: box, min: [0.52, 0.25], max: [0.72, 0.45]},\n"
      "     material: {type: linear_elastic, E: 1.0e6, nu: 0.3, density: 1000},\n"
      "     velocity: [-1.0, 0]}\n"
      "contact: {type: friction, coefficient: 0.3}\n"
      "time: {end: 0.3}\n"
      "output: {every_time: 1.0, history_every: 1, history_digits: 17, energy_balance: true}\n";
  const std::string footing =
      "grid: {origin: [0, 0], extent: [1.0, 0.6], cell_size: 0.05}\n"
      "gravity: [0, -9.81]\n"
      "bodies:\n"
      "  - {name: soil, generator: {type: box, min: [0, 0], max: [1.0, 0.3]},\n"
      "     material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}}\n"
      "  - {name: footing, generator: {type: box, min: [0.4, 0.3], max: [0.6, 0.4]},\n"
      "     material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}}\n"
      "boundaries:\n  - {type: fixed, face: y-, name: base}\n"
      "  - {type: slip, face: x-}\n  - {type: slip, face: x+}\n"
      "  - {type: rigid_body, body: footing, velocity: [0, -0.05], name: footing}\n"
      "time: {end: 0.4}\n"
      "output: {every_time: 1.0, history_every: 1, history_digits: 17, energy_balance: true}\n";
  for (const auto& [name, yaml] :
       std::vector<std::pair<std::string, std::string>>{{"rigid block on a slab", slab},
                                                        {"collision", collision},
                                                        {"bonded footing", footing}}) {
    TempDir dir("mpi_contact");
    fs::create_directories(dir.path);
    std::ofstream(dir.path / "run.yaml") << yaml;
    const auto serial = run_on(dir.path, "serial", 0);
    INFO(name << "\n" << serial.output);
    REQUIRE(serial.exit_code == 0);
    const auto h0 = loam_test::read_csv_columns(dir.path / "serial" / "history.csv");
    for (int ranks : {2, 4}) {
      const std::string out = "np" + std::to_string(ranks);
      const auto r = run_on(dir.path, out, ranks);
      INFO(r.output);
      REQUIRE(r.exit_code == 0);
      const auto h = loam_test::read_csv_columns(dir.path / out / "history.csv");
      // Each column against the largest serial magnitude of its family (reactions, momenta,
      // energies): a component that is round-off serially (a footing's horizontal reaction)
      // is measured against what its family carries.
      auto family = [](const std::string& c) {
        return c.rfind("reaction_", 0) == 0   ? 1
               : c.rfind("momentum_", 0) == 0 ? 2
               : c == "time"                  ? 3
                                              : 0;
      };
      double scale[4] = {};
      for (const auto& [column, v0] : h0)
        for (double x : v0) scale[family(column)] = std::max(scale[family(column)], std::fabs(x));
      double worst = 0;
      std::string where;
      for (const auto& [column, v0] : h0) {
        if (column == "step" || column == "dt" || column == "particles") continue;
        REQUIRE(h.count(column));
        const auto& v = h.at(column);
        REQUIRE(v.size() == v0.size());
        double diff = 0;
        for (size_t k = 0; k < v0.size(); ++k) diff = std::max(diff, std::fabs(v[k] - v0[k]));
        if (diff / scale[family(column)] > worst)
          worst = diff / scale[family(column)], where = column;
      }
      std::printf("%s on %d ranks: %zu history rows, largest difference from serial %.2e (%s)\n",
                  name.c_str(), ranks, h0.at("time").size(), worst, where.c_str());
      CHECK(worst <= 1e-9);
    }
  }
}

TEST_CASE("mpirun: a CPDI domain that outgrows the ghost layer stops every rank with the reason",
          "[mpi][mpi_run][cpdi]") {
  // docs/parallel.md: under mpirun CPDI runs with gimp's ghost layer (one row below, two above),
  // which holds its stencils while every domain's half-extent is below a cell. A bar of one
  // point per cell (domain half-size h/2) pulled apart at a stretch rate of 2/s reaches a
  // half-extent of one cell at stretch 2, t = 0.5 s; serially it runs on to stretch 3 (below
  // max_stretch 4).
  TempDir dir("mpi_cpdi_reach");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [-1], extent: [3], cell_size: 0.1}\nshape_function: cpdi\n"
         "bodies:\n  - name: bar\n    generator: {type: box, min: [0], max: [1]}\n"
         "    particles_per_cell: 1\n"
         "    material: {type: linear_elastic, E: 1, nu: 0, density: 1000}\n"
         "    velocity: {type: linear_profile, value: [0], gradient: [2], axis: 0, origin: "
         "0.5}\n"
         "time: {end: 1.0, dt: 1.0e-3}\noutput: {every_time: 0.5, fields: [velocity]}\n";
  const auto serial = run_on(dir.path, "serial", 0);
  INFO(serial.output);
  CHECK(serial.exit_code == 0);
  const auto r = run_on(dir.path, "np2", 2);
  std::printf("cpdi domain beyond the ghost layer at 2 ranks: exit %d\n%s", r.exit_code,
              r.output.c_str());
  CHECK(r.exit_code != 0);
  CHECK(r.output.find("under mpirun the ranks exchange a ghost layer of one cell") !=
        std::string::npos);
}

TEST_CASE("mpirun: what does not run on ranks yet is refused with located errors, writing nothing",
          "[mpi][mpi_run][bad_config]") {
  // docs/parallel.md "What runs on ranks": a plugin that does not declare runs_on_ranks (every
  // plugin of loam does; here an out-of-tree reference written before the ranks existed,
  // tests/plugins/stateless_reference.cpp) is an error at its place in the file, exit 2, before
  // any output; so are a selection too deep for a traction across the cut, a grid periodic
  // along every axis and a grid too thin for the ranks.
  TempDir dir("mpi_refused_features");
  fs::create_directories(dir.path);
  std::ofstream(dir.path / "run.yaml")
      << "plugins: [" LOAM_STATELESS_REFERENCE
         "]\n"
         "grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.05}\n"
         "bodies:\n"
         "  - name: block\n"
         "    generator: {type: box, min: [0.2, 0.2], max: [0.6, 0.6]}\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "time: {end: 0.1}\n"
         "verify: {type: test_peak_speed}\n";
  check_refused(dir.path, 2,
                {"run.yaml:8:9: error: verify: 'test_peak_speed' does not run under mpirun yet"});

  // A traction on a selection two particle layers deep across the cut between 2 blocks
  // (x = 0.5 m): the layers are on different ranks, and the check gathers them.
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [0, 0], extent: [1, 1], cell_size: 0.05}\n"
         "bodies:\n  - name: block\n    generator: {type: box, min: [0.2, 0.2], max: [0.6, "
         "0.6]}\n    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "selections:\n  - {name: side, min: [0.475, 0.2], max: [0.525, 0.6]}\n"
         "loads:\n  - {type: traction, selection: side, face: x+, traction: [1, 0]}\n"
         "time: {end: 0.1}\n";
  check_refused(dir.path, 2,
                {"run.yaml:9:33: error: loads.0.selection: selection 'side' is more than one "
                 "particle layer deep along the face normal (particles at x = 0.4875 and 0.5125 "
                 "m on one line)"});

  // A 1D periodic grid: the ranks keep a periodic axis whole, and there is no other.
  std::ofstream(dir.path / "run.yaml")
      << "grid: {origin: [0], extent: [1], cell_size: 0.1}\n"
         "bodies:\n  - name: bar\n    generator: {type: box, min: [0], max: [1]}\n"
         "    material: {type: linear_elastic, E: 1000, nu: 0.3, density: 1000}\n"
         "boundaries:\n  - {type: periodic, axis: x}\n"
         "time: {end: 0.1}\n";
  check_refused(dir.path, 2,
                {"run.yaml:1:7: error: grid: the grid is periodic along every axis: no axis is "
                 "left to split over 2 ranks (run it on one)"});

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
