#pragma once
// The state of one run and the hooks schemes call. A scheme owns the order of a step; this class
// owns everything else: grid, particles, plugins, time, partition, and the points where boundary
// conditions, loads and damping act (DESIGN.md "The step, and where plugins hook in").
#include <omp.h>

#include <array>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "damping.hpp"
#include "diagnostics.hpp"
#include "energies.hpp"
#include "field.hpp"
#include "generator.hpp"
#include "grid.hpp"
#include "load.hpp"
#include "material.hpp"
#include "params.hpp"
#include "particles.hpp"
#include "partition.hpp"
#include "reference.hpp"
#include "scheme.hpp"
#include "shape_function.hpp"
#include "writer.hpp"

namespace loam {

struct Body {
  std::string name;
  Params params;
  size_t first_id = 0, count = 0;    // particle ids [first_id, first_id + count)
  std::vector<double> lower, upper;  // bounding box of the particles' domains
  std::vector<double> spacing;       // particle spacing per axis
};

template <int D>
class Simulation {
 public:
  using Vec = std::array<double, D>;

  /// Build from a validated config. Semantic errors (particles outside the grid, unknown body
  /// names, ...) and plugin set-up errors go to `diag`; nothing runs if it is not ok().
  Simulation(const Params& config, int threads, Diagnostics& diag);
  ~Simulation();

  Params config;
  Grid<D> grid;
  Particles<D> particles;
  Partition<D> partition;
  std::unique_ptr<ShapeFunction<D>> shape;
  std::unique_ptr<Scheme<D>> scheme;
  std::vector<std::unique_ptr<Material<D>>> materials;  // one per body, index = material id
  std::vector<Body> bodies;
  std::vector<std::unique_ptr<Boundary<D>>> boundaries;
  std::vector<std::unique_ptr<Load<D>>> loads;
  std::unique_ptr<Damping<D>> damping;
  std::unique_ptr<Reference<D>> reference;
  /// The faces the boundary conditions hold (Boundary::holds_face), collected at set-up: schemes
  /// pass every particle move through held_faces.moved.
  HeldFaces<D> held_faces;

  Vec gravity{};
  double time = 0, dt = 0, end_time = 0, cfl = 0.5, fixed_dt = 0;
  long max_steps = 100000000;  // time.max_steps
  long step = 0;
  int threads = 1;
  int sort_every = 20;
  double mass_tolerance = 1e-12;  // nodes lighter than this (kg) get no velocity
  double max_speed = 0;           // largest particle speed, maintained by the scheme's gather
  int external_force = -1;        // particle field handle, or -1 if no load uses it
  bool model_checked = false;     // grid and plugins were set up (output checks may run)
  /// Set by a plugin that cannot continue (e.g. "particle 12: CPDI domain inverted"); the runner
  /// stops with exit code 3 after the current step, naming step and time.
  std::string failure;

  bool profiling = false;
  std::map<std::string, double> profile;  // seconds per phase, when profiling
  /// Run f, adding its wall time to profile[phase] when profiling.
  template <class F>
  void timed(const char* phase, F&& f) {
    if (!profiling) return f();
    const double t0 = omp_get_wtime();
    f();
    profile[phase] += omp_get_wtime() - t0;
  }

  // --------------------------------------------------------- hooks for schemes
  /// Apply every boundary condition that acts on `phase` (0: the only phase or the solid, 1: the
  /// pore water) to a nodal vector: mechanical conditions first, then hydraulic ones. Here the
  /// conditions only hold components (zeroing commutes, so the order of the config does not
  /// matter); friction impulses belong to the grid update.
  void constrain(const NodalVector& v, int phase = 0) const {
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& b : boundaries)
        if (b->hydraulic() == (pass == 0) && b->applies_to(phase)) b->before_constrain(v, phase);
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& b : boundaries)
        if (b->hydraulic() == (pass == 1) && b->applies_to(phase)) b->constrain(v);
  }
  /// Apply every boundary condition to the grid update of a step (velocities, accelerations
  /// and nodal masses of every phase), in passes, so that the result does not depend on the
  /// order of the config at edges and corners where several faces meet:
  ///  1. before_constraints of every condition (face forces are in already: add_forces),
  ///     each recording the unconstrained state it needs (a friction face: v_n, whose mu |v_n|
  ///     is its budget whatever another face does to v_n);
  ///  2. the kinematic pass of the mechanical conditions (constrain_grid_update): holds,
  ///     unilateral contact, dashpots; each marks the components it holds per node in held_;
  ///  3. the Coulomb pass (coulomb_update): friction in the tangential components no condition
  ///     holds at the node (Bardenhagen et al. 2000: normal constraint, then the Coulomb impulse
  ///     in the remaining free subspace; several friction faces scale the same free vector, so
  ///     their order does not matter either);
  ///  4. the hydraulic conditions on the water.
  void constrain_update(const GridUpdate& update) const {
    GridUpdate u = update;
    for (int k = 0; k < u.count; ++k) {
      held_[size_t(k)].clear(grid.num_nodes);
      u.held[size_t(k)] = &held_[size_t(k)];
    }
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& b : boundaries)
        if (b->hydraulic() == (pass == 0)) b->before_constraints(u);
    for (const auto& b : boundaries)
      if (!b->hydraulic()) b->constrain_grid_update(u);
    for (const auto& b : boundaries)
      if (!b->hydraulic()) b->coulomb_update(u);
    for (const auto& b : boundaries)
      if (b->hydraulic()) b->constrain_grid_update(u);
  }
  /// The material stress update of one block [b, b + count) (one material per block), with
  /// its velocity gradient L in block layout (MaterialBatch).
  void update_block_stress(size_t b, int count, double dt, const double* L) {
    MaterialBatch<D> batch;
    batch.begin = b;
    batch.count = count;
    batch.dt = dt;
    batch.L = L;
    batch.particles = &particles;
    materials[particles.material[b]]->update_stress(batch);
  }
  /// Face forces of the boundary conditions (GridForces), before the grid update.
  void apply_boundary_forces(const GridForces& f) const {
    for (const auto& b : boundaries) b->add_forces(f);
  }
  void apply_grid_loads(const NodalVector& force) {
    for (const auto& l : loads) l->apply_to_grid(*this, force, time);
  }
  void apply_damping(const NodeForces& nf) {
    if (damping) damping->apply(*this, nf);
  }
  template <class F>
  void scatter_blocks(F&& f) const {
    partition.scatter_blocks(std::forward<F>(f));
  }
  template <class F>
  void gather_blocks(F&& f) const {
    partition.gather_blocks(std::forward<F>(f));
  }

  // --------------------------------------------------------- loop pieces (used by the runner)
  double stable_dt() const;
  /// Zero and refill particle external forces from loads (only if a load uses them).
  void prepare_particle_loads();
  /// Re-sort particles now.
  void sort();
  /// After a step: keep the partition valid and sort periodically.
  void maintain_partition();
  /// Kinetic, stored and gravity energy and momentum of every particle set and phase: the
  /// particles' own (mass, velocity), the materials' strain energy, and the scheme's share
  /// (Scheme::add_energies: e.g. the pore water of a two-phase scheme).
  Energies energies() const;

  /// Particle index of an original id (valid until the next sort).
  size_t index_of(uint32_t id) const;
  /// Ids of particles inside a named particle set; empty name = all. Returns false if unknown.
  bool particle_set(const std::string& name, std::vector<uint32_t>& ids) const;
  int body_index(const std::string& name) const;
  /// The body a plugin names with `key` (the first body when the key is absent), or -1 after a
  /// located "unknown body" error listing the bodies.
  int body_param(const Params& p, const std::string& key, Diagnostics& diag) const;

  /// First particle whose position, velocity or stress is not finite, or that left the grid:
  /// returns false and fills a description.
  bool check_particles(std::string& what) const;

 private:
  void build_grid(const Params& g, Diagnostics& diag);
  void generate_bodies(Diagnostics& diag);
  void initialize_fields(Diagnostics& diag);  // bodies[].initial
  void create_plugins(Diagnostics& diag);
  std::vector<std::pair<std::string, std::pair<Vec, Vec>>> sets_;
  mutable std::vector<uint32_t> index_of_id_;
  mutable std::array<HeldComponents, 2> held_;  // per phase, scratch of constrain_update
  mutable bool index_valid_ = false;
  long last_sort_ = 0;
};

}  // namespace loam
