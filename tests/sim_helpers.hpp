#pragma once
// Build a Simulation directly from YAML text, for unit tests of plugins through the C++ API.
#include <memory>
#include <stdexcept>
#include <string>

#include <yaml-cpp/yaml.h>
#include <catch2/catch.hpp>

#include "framework/config.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam_test {

template <int D>
std::unique_ptr<loam::Simulation<D>> make_simulation(const std::string& yaml, int threads = 1) {
  loam::Diagnostics diag;
  loam::LoadedConfig cfg = loam::load_config_text(yaml, "<test>", {}, diag);
  if (!diag.ok()) throw std::runtime_error(diag.format());
  if (cfg.dimension != D) throw std::runtime_error("wrong dimension in test config");
  auto sim = std::make_unique<loam::Simulation<D>>(cfg.params, threads, diag);
  if (!diag.ok()) throw std::runtime_error(diag.format());
  return sim;
}

/// Advance n steps at the stable time step with Simulation::advance, the runner's step (with its
/// stability checks; no output). Throws with the failure message if the run cannot go on.
template <int D>
void advance(loam::Simulation<D>& sim, int steps) {
  for (int i = 0; i < steps; ++i)
    if (!sim.advance(sim.stable_dt())) throw std::runtime_error(sim.failure);
}

/// Every particle of every set (velocity, and water_velocity where the scheme has it) in the
/// rigid rotation v = omega x (x - c) about (cx, cy) in 2D.
inline void set_rigid_rotation(loam::Simulation<2>& sim, double omega, double cx, double cy) {
  for (auto& set : sim.sets) {
    auto& P = set.particles;
    const int w = P.find("water_velocity");
    for (size_t i = 0; i < P.size(); ++i) {
      const double vx = -omega * (P.col(P.position, 1)[i] - cy),
                   vy = omega * (P.col(P.position, 0)[i] - cx);
      P.col(P.velocity, 0)[i] = vx;
      P.col(P.velocity, 1)[i] = vy;
      if (w >= 0) P.col(w, 0)[i] = vx, P.col(w, 1)[i] = vy;
    }
  }
}

/// A reference plugin from its `verify:` YAML text, set up on `sim` (REQUIREs no errors).
template <int D>
std::unique_ptr<loam::Reference<D>> make_reference(loam::Simulation<D>& sim,
                                                   const std::string& yaml) {
  loam::ValidationContext ctx;
  ctx.file = "verify.yaml";
  ctx.dimension = D;
  loam::Diagnostics diag;
  loam::Params p = loam::validate_plugin(YAML::Load(yaml), "reference", loam::kDimension, "verify",
                                         loam::Location{"verify.yaml", 1, 1}, ctx, diag);
  REQUIRE(diag.ok());
  auto ref = loam::Registry::instance().create<loam::Reference, D>(p);
  ref->setup(sim, diag);
  REQUIRE(diag.ok());
  return ref;
}

}  // namespace loam_test
