// Throughput benchmark (not part of the core: its scenes name concrete plugins): an elastic block
// under gravity on a fixed base, ~100k particles, a fixed number of steps after a short warm-up,
// reported as particle-steps per second (the project rule: speed lives in benchmarks, never in
// timed unit tests).
#include "bench.hpp"

#include <algorithm>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "framework/config.hpp"
#include "framework/registry.hpp"
#include "framework/runner.hpp"

namespace loam {

namespace {

/// The block's body split at x = 0.5 m into bodies `a` and `b` in sets `a` and `b`.
std::string split_into_two_sets(std::string yaml) {
  auto replace = [&](const std::string& from, const std::string& to) {
    const size_t k = yaml.find(from);
    if (k == std::string::npos) return false;
    yaml.replace(k, from.size(), to);
    return true;
  };
  if (yaml.empty() ||
      !replace("scheme: {type: single_phase,", "scheme: {type: single_phase, sets: [a, b],"))
    return "";
  const size_t b0 = yaml.find("  - name: block\n"), b1 = yaml.find("boundaries:");
  std::string body = yaml.substr(b0, b1 - b0);
  const size_t g0 = body.find("min: ["), g1 = body.find("max: [");
  std::string a = body, b = body;
  // min: [0, ...] max: [1.0, ...]: a ends, b starts at x = 0.5.
  a.replace(g1 + 6, 3, "0.5");
  b.replace(g0 + 6, 1, "0.5");
  a.replace(a.find("name: block"), 11, "name: a\n    set: a");
  b.replace(b.find("name: block"), 11, "name: b\n    set: b");
  yaml.replace(b0, b1 - b0, a + b);
  return yaml;
}

/// The block as the solid set of the double-point scheme and a body of water over the same box
/// in the liquid set: a saturated block with a solid and a liquid point in every place.
std::string saturate_with_liquid_points(std::string yaml) {
  const size_t b0 = yaml.find("  - name: block\n"), b1 = yaml.find("boundaries:");
  if (b0 == std::string::npos || b1 == std::string::npos) return "";
  std::string solid = yaml.substr(b0, b1 - b0), water = solid;
  solid.replace(solid.find("name: block"), 11, "name: block\n    set: solid");
  water.replace(water.find("name: block"), 11, "name: water\n    set: liquid");
  const size_t m0 = water.find("material: {"), m1 = water.find('}', m0);
  water.replace(m0, m1 - m0 + 1,
                "material: {type: newtonian_fluid, bulk_modulus: 2.2e9, viscosity: 1.0e-3, "
                "density: 1000}");
  yaml.replace(b0, b1 - b0, solid + water);
  return yaml;
}

}  // namespace

std::string bench_scene(const std::string& scene, const std::string& shape,
                        const std::string& update) {
  // 2D: 160 x 160 cells of block, 2 x 2 particles per cell = 102 400 particles.
  // 3D: 24 x 24 x 22 cells of block, 2 x 2 x 2 particles per cell = 101 376 particles.
  // Two-phase variants: the same block, saturated (n = 0.4, k = 1e-4 m/s, K_w = 2.2 GPa).
  // The _two_sets suffix splits the block at the middle of its first axis into two bodies in two
  // particle sets (single_phase sums them onto one grid): the cost of a set against one set.
  const std::string suffix = "_two_sets";
  if (scene.size() > suffix.size() &&
      scene.compare(scene.size() - suffix.size(), suffix.size(), suffix) == 0)
    return split_into_two_sets(
        bench_scene(scene.substr(0, scene.size() - suffix.size()), shape, update));
  // The double_point_ prefix: the block saturated with liquid points (the double-point scheme,
  // MUSL only; a solid and a liquid point per place, so twice the particles).
  const std::string prefix = "double_point_";
  if (scene.rfind(prefix, 0) == 0) {
    std::string yaml = bench_scene(scene.substr(prefix.size()), shape, update);
    const std::string from = "scheme: {type: single_phase, update: " + update + "}";
    const size_t k = yaml.find(from);
    if (yaml.empty() || k == std::string::npos) return "";
    yaml.replace(k, from.size(),
                 "scheme: {type: two_phase_double_point, porosity: 0.4, drag: {type: darcy, "
                 "hydraulic_conductivity: 1.0e-4}}");
    return saturate_with_liquid_points(yaml);
  }
  // The apic_ and tpic_ prefixes: any scene with that affine transfer added to its scheme, with
  // the --update given (linear tents: usf only); fbar_: with volumetric: fbar.
  const std::pair<const char*, const char*> options[] = {{"apic_", ", transfer: apic"},
                                                         {"tpic_", ", transfer: tpic"},
                                                         {"fbar_", ", volumetric: fbar"}};
  for (const auto& [option, setting] : options) {
    const std::string prefix_of = option;
    if (scene.rfind(prefix_of, 0) != 0) continue;
    std::string yaml = bench_scene(scene.substr(prefix_of.size()), shape, update);
    const size_t line = yaml.find("scheme: {");
    const size_t end = line == std::string::npos ? line : yaml.find('\n', line);
    const size_t close = end == std::string::npos ? end : yaml.rfind('}', end);
    if (yaml.empty() || close == std::string::npos || close < line) return "";
    yaml.insert(close, setting);  // the scheme map's last brace
    return yaml;
  }
  const bool two_phase = scene.rfind("two_phase_", 0) == 0;
  const std::string base = two_phase ? scene.substr(10) : scene;
  const std::string scheme =
      two_phase ? "{type: two_phase_single_point, porosity: 0.4, water_bulk_modulus: 2.2e9, "
                  "drag: {type: darcy, hydraulic_conductivity: 1.0e-4}, update: " +
                      update + "}"
                : "{type: single_phase, update: " + update + "}";
  // The bench stops after --steps: `end` is only a far horizon, so lift the step budget
  // (time.max_steps) that would refuse a stiff scene's 1000 s.
  std::string common = "shape_function: " + shape + "\nscheme: " + scheme +
                       "\ntime: {end: 1.0e3, cfl: 0.5, max_steps: 1000000000000}\n";
  if (base == "elastic_block_2d")
    return common + R"(grid: {origin: [0, 0], extent: [1.0, 1.1], cell_size: 0.00625}
gravity: [0, -9.81]
bodies:
  - name: block
    generator: {type: box, min: [0, 0], max: [1.0, 1.0]}
    particles_per_cell: 2
    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}
boundaries:
  - {type: fixed, face: y-}
  - {type: slip, face: x-}
  - {type: slip, face: x+}
)";
  if (base == "elastic_block_3d")
    return common +
           R"(grid: {origin: [0, 0, 0], extent: [1.0, 1.0, 1.0], cell_size: 0.0416666666666667}
gravity: [0, 0, -9.81]
bodies:
  - name: block
    generator: {type: box, min: [0, 0, 0], max: [1.0, 1.0, 0.9166666666666667]}
    particles_per_cell: 2
    material: {type: linear_elastic, E: 1.0e7, nu: 0.3, density: 2000}
boundaries:
  - {type: fixed, face: z-}
  - {type: slip, face: x-}
  - {type: slip, face: x+}
  - {type: slip, face: y-}
  - {type: slip, face: y+}
)";
  return "";
}

int run_scene(const BenchOptions& opt, const std::string& scene, const std::string& shape);

int run_bench(const BenchOptions& opt) {
  if (!opt.materials.empty()) return run_material_bench(opt);
  int status = 0;
  std::vector<std::string> shapes = opt.shapes;
  if (shapes.size() == 1 && shapes[0] == "all")
    shapes = Registry::instance().names("shape_function");
  for (const auto& shape : shapes)
    for (const auto& scene : opt.scenes) status = std::max(status, run_scene(opt, scene, shape));
  return status;
}

int run_scene(const BenchOptions& opt, const std::string& scene, const std::string& shape) {
  int status = 0;
  {
    std::string yaml = bench_scene(scene, shape, opt.update);
    if (yaml.empty()) {
      std::fprintf(stderr,
                   "loam: error: unknown bench scene '%s' (elastic_block_2d, elastic_block_3d, "
                   "two_phase_elastic_block_2d, two_phase_elastic_block_3d; prefix "
                   "double_point_: the block saturated with liquid points; prefixes apic_, "
                   "tpic_: that transfer, fbar_: volumetric: fbar; suffix _two_sets: the block "
                   "split over two particle sets)\n",
                   scene.c_str());
      return 2;
    }
    Diagnostics diag;
    LoadedConfig cfg = load_config_text(yaml, "<bench " + scene + ">", {}, diag);
    if (!diag.ok()) {
      std::fputs(diag.format().c_str(), stderr);
      return 2;
    }
    for (int threads : opt.threads) {
      std::vector<nlohmann::json> runs;
      for (int r = 0; r < opt.repeat; ++r) {
        RunOptions ro;
        ro.threads = threads;
        ro.quiet = true;
        ro.report = false;  // the benchmark prints its own lines (--json: only JSON)
        ro.write_output = false;
        ro.max_steps = 20;  // warm-up: first sorts, page faults, caches
        ro.profile = opt.profile;
        RunResult warm = run_config(cfg, ro);
        ro.max_steps = opt.steps;
        RunResult res = run_config(cfg, ro);
        if (res.exit_code) {
          std::fputs(res.message.c_str(), stderr);
          status = res.exit_code;
          continue;
        }
        runs.push_back(res.summary);
      }
      if (runs.empty()) continue;
      std::sort(runs.begin(), runs.end(), [](const auto& a, const auto& b) {
        return a["particle_steps_per_second"].template get<double>() <
               b["particle_steps_per_second"].template get<double>();
      });
      const auto& s = runs[runs.size() / 2];  // median
      nlohmann::json j;
      j["scene"] = scene;
      j["dimension"] = s["dimension"];
      j["shape_function"] = s["shape_function"];
      j["scheme"] = s["scheme"];
      j["update"] = opt.update;
      j["particles"] = s["particles"];
      j["steps"] = s["steps"];
      j["threads"] = threads;
      j["particle_steps_per_second"] = s["particle_steps_per_second"];
      j["bytes_per_particle"] = s["bytes_per_particle"];
      j["repeats"] = opt.repeat;
      if (s.contains("profile_seconds")) {
        nlohmann::json prof;
        double wall = s["wall_seconds"].get<double>();
        for (const auto& [k, v] : s["profile_seconds"].items()) prof[k] = v.get<double>() / wall;
        j["profile_fraction"] = prof;
      }
      if (opt.json) {
        std::printf("%s\n", j.dump().c_str());
      } else {
        std::printf(
            "%-18s %dD %-8s %-5s %zu particles, %ld steps, %d thread(s): %7.2f M particle-steps/s, "
            "%zu B/particle\n",
            scene.c_str(), s["dimension"].get<int>(), shape.c_str(), opt.update.c_str(),
            s["particles"].get<size_t>(), s["steps"].get<long>(), threads,
            s["particle_steps_per_second"].get<double>() / 1e6,
            s["bytes_per_particle"].get<size_t>());
        if (j.contains("profile_fraction"))
          std::printf("    profile: %s\n", j["profile_fraction"].dump().c_str());
      }
      std::fflush(stdout);
    }
  }
  return status;
}

}  // namespace loam
