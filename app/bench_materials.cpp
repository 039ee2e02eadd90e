// Stress-update cost per material (`loam bench --materials`): each material plugin updates a
// batch of 32 768 particles of a 3D sample, block by block as a scheme calls it, along two
// phases measured separately: an elastic phase (tiny isotropic unloading increments) and a
// plastic phase (undrained compression far beyond failure, 1e-4 axial strain per step). Reports
// nanoseconds per particle update on one thread (the schemes parallelise over blocks).
#include <omp.h>

#include <cstdio>
#include <nlohmann/json.hpp>

#include "bench.hpp"
#include "framework/config.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

namespace {

struct MaterialCase {
  const char* name;
  const char* yaml;
};

// Representative parameters (the element-test examples of each model).
const MaterialCase kCases[] = {
    {"linear_elastic", "{type: linear_elastic, E: 20.0e6, nu: 0.3, density: 2000}"},
    {"mohr_coulomb",
     "{type: mohr_coulomb, E: 20.0e6, nu: 0.3, density: 2000, c: 5000, phi: 30, psi: 10}"},
    {"drucker_prager",
     "{type: drucker_prager, E: 20.0e6, nu: 0.3, density: 2000, c: 5000, phi: 30, psi: 10}"},
    {"strain_softening_mc",
     "{type: strain_softening_mc, E: 20.0e6, nu: 0.3, density: 2000, c_peak: 5000, "
     "phi_peak: 35, psi_peak: 5, c_residual: 0, phi_residual: 25, psi_residual: 0, "
     "softening_start: 0, softening_end: 0.1}"},
    {"modified_cam_clay",
     "{type: modified_cam_clay, lambda: 0.2, kappa: 0.04, M: 1.2, nu: 0.3, e0: 1.0, ocr: 1, "
     "density: 1800}"},
    {"newtonian_fluid",
     "{type: newtonian_fluid, bulk_modulus: 2.2e9, viscosity: 1.0e-3, density: 1000}"},
};

/// Nanoseconds per particle update over `steps` steps of the velocity gradient L (3x3, dt = 1).
double time_updates(Simulation<3>& sim, const double (&L)[3][3], int steps) {
  auto& P = sim.sets[0].particles;
  std::vector<double> Lb(9 * kBlock);
  for (int k = 0; k < 9; ++k)
    for (int p = 0; p < kBlock; ++p) Lb[size_t(k) * kBlock + size_t(p)] = L[k / 3][k % 3];
  MaterialBatch<3> batch;
  batch.L = Lb.data();
  batch.particles = &P;
  batch.dt = 1.0;
  const double t0 = omp_get_wtime();
  for (int s = 0; s < steps; ++s)
    for (size_t b = 0; b < P.size(); b += kBlock) {
      batch.begin = b;
      batch.count = int(std::min<size_t>(kBlock, P.size() - b));
      sim.materials[0]->update_stress(batch);
    }
  return (omp_get_wtime() - t0) * 1e9 / (double(steps) * double(P.size()));
}

}  // namespace

int run_material_bench(const BenchOptions& opt) {
  int status = 0;
  for (const auto& c : kCases) {
    if (!opt.materials.empty() && opt.materials != "all" && opt.materials != c.name) continue;
    if (!Registry::instance().find("material", c.name)) continue;
    const std::string yaml =
        std::string("grid: {extent: [1.0, 1.0, 0.125], cell_size: 0.03125}\n") +
        "bodies:\n  - name: sample\n    generator: {type: box, min: [0, 0, 0], "
        "max: [1.0, 1.0, 0.125]}\n    particles_per_cell: 2\n    material: " +
        c.yaml + "\ntime: {end: 1}\n";
    Diagnostics diag;
    LoadedConfig cfg = load_config_text(yaml, std::string("<bench ") + c.name + ">", {}, diag);
    if (!diag.ok()) {
      std::fputs(diag.format().c_str(), stderr);
      status = 2;
      continue;
    }
    std::vector<double> elastic, plastic;
    for (int r = 0; r < opt.repeat; ++r) {
      Simulation<3> sim(cfg.params, 1, diag);
      auto& P = sim.sets[0].particles;
      for (int k = 0; k < 6; ++k)
        for (size_t i = 0; i < P.size(); ++i) P.col(P.stress, k)[i] = k < 3 ? -100e3 : 0.0;
      sim.materials[0]->initialize(P, 0, P.size());
      const double unload[3][3] = {{1e-8, 0, 0}, {0, 1e-8, 0}, {0, 0, 1e-8}};
      const double shear[3][3] = {{-1e-4, 2e-5, 0}, {0, 0.5e-4, 0}, {0, 0, 0.5e-4}};
      elastic.push_back(time_updates(sim, unload, 50));
      time_updates(sim, shear, 300);  // load to failure (3 % axial strain), not timed
      plastic.push_back(time_updates(sim, shear, 50));
    }
    std::sort(elastic.begin(), elastic.end());
    std::sort(plastic.begin(), plastic.end());
    nlohmann::json j;
    j["material"] = c.name;
    j["particles"] = 32768;
    j["threads"] = 1;
    j["ns_per_update_elastic"] = elastic[elastic.size() / 2];
    j["ns_per_update_plastic"] = plastic[plastic.size() / 2];
    j["repeats"] = opt.repeat;
    if (opt.json)
      std::printf("%s\n", j.dump().c_str());
    else
      std::printf(
          "%-20s 3D stress update, 1 thread: elastic %7.1f ns/particle, plastic %7.1f "
          "ns/particle\n",
          c.name, elastic[elastic.size() / 2], plastic[plastic.size() / 2]);
    std::fflush(stdout);
  }
  return status;
}

}  // namespace loam
