#pragma once
// One stage of a staged analysis (docs/stages.md): what changes at its start and when it ends.
// The plugins a stage brings (loads, boundary conditions, damping, materials) are created and set
// up with the model, so that every error is reported before the run starts; at the stage's start
// Simulation::begin_stage swaps them with the running ones.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "boundary.hpp"
#include "damping.hpp"
#include "load.hpp"
#include "material.hpp"
#include "params.hpp"

namespace loam {

template <int D>
struct Stage {
  Params params;  // its entry of `stages:` (empty for the one implicit stage of a plain run)
  std::string name;
  /// The stage's time: its duration, or with until: static the time limit (max_time).
  double duration = 0;
  bool until_static = false;
  bool stop_if_not_static = true;
  double static_speed = 1e-5;  // m/s
  double static_window = 0;    // s; 0: a P-wave's crossing time at the stage's start

  // Changes at the stage's start (a flag false: unchanged from the previous stage).
  bool sets_loads = false, sets_boundaries = false, sets_damping = false, sets_output = false;
  std::vector<std::unique_ptr<Load<D>>> loads;
  std::vector<std::unique_ptr<Boundary<D>>> boundaries;
  std::unique_ptr<Damping<D>> damping;
  struct MaterialChange {
    int body = -1;
    std::unique_ptr<Material<D>> material;
    bool new_type = false;  // another model: its state is initialised from the current stress
  };
  std::vector<MaterialChange> materials;
  std::vector<int> activate, deactivate;  // body indices
  bool reset_displacement = false, reset_velocity = false, reset_plastic_strain = false;
  long every_steps = 0;   // with sets_output
  double every_time = 0;  // with sets_output
};

}  // namespace loam
