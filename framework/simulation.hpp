#pragma once
// The state of one run and the hooks schemes call. A scheme owns the order of a step; this class
// owns everything else: grid, particle sets, plugins, time, and the points where boundary
// conditions, loads and damping act (docs/architecture.md "The step").
#include <omp.h>

#include <array>
#include <limits>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "boundary.hpp"
#include "contact.hpp"
#include "damping.hpp"
#include "diagnostics.hpp"
#include "energies.hpp"
#include "energy_ledger.hpp"
#include "field.hpp"
#include "generator.hpp"
#include "grid.hpp"
#include "load.hpp"
#include "material.hpp"
#include "params.hpp"
#include "particle_set.hpp"
#include "ranks.hpp"
#include "reactions.hpp"
#include "reference.hpp"
#include "rigid_records.hpp"
#include "scheme.hpp"
#include "shape_function.hpp"
#include "sink.hpp"
#include "source.hpp"
#include "stage.hpp"
#include "writer.hpp"

namespace loam {

struct Body {
  std::string name;
  Params params;
  size_t first_id = 0, count = 0;    // particle ids [first_id, first_id + count)
  size_t local_count = 0;            // of those, the particles this rank holds (all serially)
  std::vector<double> lower, upper;  // bounding box of the particles' domains
  std::vector<double> spacing;       // particle spacing per axis
  int set = 0;                       // index into Simulation::sets
  size_t first_index = 0;            // index of its first particle in its set before any sort
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
  /// The ranks the run is split over (framework/ranks.hpp): one serially, and then every call
  /// to it is the identity. Declared after the grid, whose box it keeps (destroyed first).
  std::unique_ptr<Ranks<D>> ranks = make_ranks<D>();
  /// The particle sets, in the order the scheme declares them; created before any plugin set-up
  /// and never added to or removed afterwards (references to them stay valid).
  std::vector<ParticleSet<D>> sets;
  std::unique_ptr<ShapeFunction<D>> shape;
  std::unique_ptr<Scheme<D>> scheme;
  std::vector<std::unique_ptr<Material<D>>> materials;  // one per body, index = material id
  std::vector<Body> bodies;
  std::vector<std::unique_ptr<Boundary<D>>> boundaries;
  /// The reaction of every mechanical condition of the run (its stages' included), per step.
  Reactions<D> reactions;
  /// The displacement, rotation and moment of every rigid body under contact, per step.
  RigidRecords<D> rigid_records;
  /// The energy balance's work and flows (framework/energy_ledger.hpp).
  EnergyLedger<D> ledger;
  std::vector<std::unique_ptr<Load<D>>> loads;
  std::vector<std::unique_ptr<Source<D>>> sources;
  std::vector<std::unique_ptr<Sink<D>>> sinks;
  std::unique_ptr<Damping<D>> damping;
  /// The contact law between bodies on their own velocity fields (`contact:`), or null.
  std::unique_ptr<Contact<D>> contact;
  std::unique_ptr<Reference<D>> reference;
  /// The stages of the run (`stages:`; one implicit stage of time.end without it), and the one
  /// running (-1 before the first has begun). docs/stages.md.
  std::vector<Stage<D>> stages;
  int stage = -1;
  /// When the running loads began (the start of the stage that set them): a load's time, e.g.
  /// its ramp, counts from here.
  double loads_start = 0;
  /// The faces the boundary conditions hold (Boundary::holds_face), collected at set-up: schemes
  /// pass every particle move through held_faces.moved.
  HeldFaces<D> held_faces;
  /// The faces that hold the water's own points (a double-point scheme's liquid set): those of
  /// the conditions that hold the water phase, less the faces a drained condition releases.
  HeldFaces<D> held_faces_water;

  Vec gravity{};
  double time = 0, dt = 0, end_time = 0, cfl = 0.5, fixed_dt = 0;
  long max_steps = 100000000;  // time.max_steps
  long step = 0;
  int threads = 1;
  int sort_every = 20;
  long check_every = 1;           // numerics.check_every
  double mass_tolerance = 1e-12;  // nodes lighter than this (kg) get no velocity
  double max_speed = 0;           // largest particle speed, maintained by the scheme's gather
  int external_force = -1;        // particle field handle, or -1 if no load uses it
  int deformation_gradient = -1;  // particle field handle, or -1 if nothing requested F
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
  /// Complete the nodal sums of a scatter over the ranks (Ranks::complete_nodes): a scheme calls
  /// it after each scatter, before it reads the nodes. Serially nothing happens.
  void complete_nodes(const std::vector<NodalArray>& arrays) {
    if (ranks->distributed()) timed("halo", [&] { ranks->complete_nodes(arrays); });
  }
  /// Complete per-cell sums (K values per grid cell) over the ranks (Ranks::complete_cells): a
  /// scheme calls it after summing its particles per cell after the move. Serially nothing.
  void complete_cells(std::vector<double>& sums, int K) {
    if (ranks->distributed()) timed("halo", [&] { ranks->complete_cells(sums.data(), K); });
  }
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
  ///  4. the hydraulic conditions on the water;
  ///  5. `coupling`: what a scheme does at once with the conditions' result (two-phase: the
  ///     re-solve of a free phase against a held one, follow_held_phases).
  /// The reactions (framework/reactions.hpp) are the change of all of it at the mechanical
  /// conditions' nodes.
  void constrain_update(const GridUpdate& update) {
    constrain_update(update, [] {});
  }
  template <class F>
  void constrain_update(const GridUpdate& update, F&& coupling) {
    GridUpdate u = update;
    u.time = time - loads_start;
    for (int k = 0; k < u.count; ++k) {
      held_[size_t(k)].clear(grid.num_nodes);
      u.held[size_t(k)] = &held_[size_t(k)];
    }
    for (int pass = 0; pass < 2; ++pass)
      for (const auto& b : boundaries)
        if (b->hydraulic() == (pass == 0)) b->before_constraints(u);
    ledger.begin_update(u);
    if (!reactions.empty()) reactions.begin_update(boundaries, u, grid, *ranks);
    for (const auto& b : boundaries)
      if (!b->hydraulic()) b->constrain_grid_update(u);
    for (const auto& b : boundaries)
      if (!b->hydraulic()) b->coulomb_update(u);
    for (const auto& b : boundaries)
      if (b->hydraulic()) b->constrain_grid_update(u);
    coupling();
    if (!reactions.empty()) reactions.end_update(u);
    ledger.end_update(u);
    timed("check_grid", [&] { check_grid(u); });
  }
  /// The components of `phase` the conditions held in the last constrain_update.
  const HeldComponents& held(int phase) const { return held_[size_t(phase)]; }
  /// NaN or inf on the grid is caught in the step it appears (before the transfer to the
  /// particles spreads it): one pass over each phase's nodal velocity and acceleration after the
  /// conditions, sum of 0 * value (NaN for any non-finite value, 0 otherwise), then the first
  /// such node is named in `failure`.
  void check_grid(const GridUpdate& u);

  /// The state of the last step that passed the stability check (numerics.keep_last_good): the
  /// runner writes it as the last regular frame (and checkpoint) when a later step fails. Each
  /// set's particles with the partition they were sorted into, so that a checkpoint of it
  /// continues as the run did.
  struct GoodState {
    double time = 0, dt = 0, max_speed = 0;
    long step = -1;
    std::vector<Particles<D>> sets;
    struct Layout {  // a set's partition (not its sort scratch) and sort counters
      std::vector<typename Partition<D>::Slab> slabs;
      std::vector<IndexRange> material_ranges;
      int threads = 1;
      long last_sort = 0;
      bool resized = false;
    };
    std::vector<Layout> layouts;
  };
  GoodState last_good;
  bool keep_last_good = true;
  void save_last_good();
  /// Exchange the last good state with the current one (twice: back).
  void swap_last_good();
  /// The material stress update of one block [b, b + count) (one material per block), with
  /// its velocity gradient L in block layout (MaterialBatch). The energy ledger counts the
  /// stress power V sigma : L, or V sigma : L_power where a scheme changes the volume otherwise
  /// than tr L (the double-point liquid: its storage equation).
  void update_block_stress(ParticleSet<D>& set, size_t b, int count, double dt, const double* L,
                           const double* L_power = nullptr) {
    MaterialBatch<D> batch;
    batch.begin = b;
    batch.count = count;
    batch.dt = dt;
    batch.L = L;
    batch.particles = &set.particles;
    if (!ledger.enabled) return materials[set.particles.material[b]]->update_stress(batch);
    const double* Lp = L_power ? L_power : L;
    const double before = block_stress_power(set.particles, b, count, Lp);
    materials[set.particles.material[b]]->update_stress(batch);
    ledger.add_stress_work(set_slot(set), b, before,
                           block_stress_power(set.particles, b, count, Lp), dt);
  }
  /// The index of `set` in sets.
  size_t set_slot(const ParticleSet<D>& set) const { return size_t(&set - sets.data()); }
  /// Face forces of the boundary conditions (GridForces), before the grid update.
  void apply_boundary_forces(GridForces f) {
    f.time = time - loads_start;
    for (const auto& b : boundaries)  // some add none, join nodes (periodic) or refresh
      ledger.record_if(b->adds_forces(), NodalWork::kBoundaries, f.mixture, [&] {
        reactions.measure_forces(*b, f, grid, *ranks, [&] { b->add_forces(f); });
      });
  }
  void apply_grid_loads(const NodalVector& force) {
    for (const auto& l : loads)
      ledger.record_if(l->uses_grid_forces(), NodalWork::kLoads, force,
                       [&] { l->apply_to_grid(*this, force, time - loads_start); });
  }
  /// The damping's change of the nodal forces; the nodes in `supported` (where a rigid body
  /// under contact holds another body up, ContactFields::supported_nodes) keep theirs: the
  /// support is not in their force, so damping it would carry part of the load (a block
  /// resting on a rigid plate under local damping alpha = 0.3 put 30 % less on the plate).
  void apply_damping(const NodeForces& nf, const std::vector<size_t>* supported = nullptr,
                     MomentumBalance balance = MomentumBalance::kSolid) {
    if (!damping) return;
    if (!reactions.empty()) reactions.before_damping(nf.force, grid, *ranks, balance);
    const auto act = [&] {
      if (!supported || supported->empty()) return damping->apply(*this, nf);
      std::vector<double> kept;
      for (size_t n : *supported)
        for (int d = 0; d < D; ++d) kept.push_back(nf.force.at(n, d));
      damping->apply(*this, nf);
      for (size_t k = 0; k < supported->size(); ++k)
        for (int d = 0; d < D; ++d) nf.force.at((*supported)[k], d) = kept[k * D + size_t(d)];
    };
    // The ledger prices recorded forces at the first phase's velocities; the double-point liquid's
    // work is outside the balance (docs/energy_balance.md), its damping with it.
    if (balance == MomentumBalance::kSolid)
      ledger.record(NodalWork::kDamping, nf.force, act);
    else
      act();
    if (!reactions.empty()) reactions.after_damping(nf.force, balance);
  }
  /// f(set, begin, count, thread) over the blocks of every set: race-free scatters set after
  /// set (one grid), gathers on all threads.
  template <class F>
  void scatter_blocks(F&& f) {
    for (auto& s : sets) s.scatter_blocks([&](size_t b, int c, int t) { f(s, b, c, t); });
  }
  template <class F>
  void gather_blocks(F&& f) {
    for (auto& s : sets) s.gather_blocks([&](size_t b, int c, int t) { f(s, b, c, t); });
  }

  /// A particle load's forces: external_force += force(k, d) for every particle ids[k] of set
  /// `set` that is here (a body waiting for a stage is not; under mpirun, another rank's
  /// particle is not). Loads that keep their particles by id (traction, cavity_pressure).
  template <class F>
  void add_external_forces(int set, const std::vector<uint32_t>& ids, F&& force) {
    ParticleSet<D>& s = sets[size_t(set)];
    for (size_t k = 0; k < ids.size(); ++k) {
      const size_t i = s.index_of(ids[k]);
      if (i == s.npos) continue;
      for (int d = 0; d < D; ++d) s.particles.col(external_force, d)[i] += force(k, d);
    }
  }

  // --------------------------------------------------------- particle fields
  /// Register a particle field in every set (one layout: the handle is valid in each) and
  /// allocate it in all of them, or only in set `only` (e.g. a material's state in the set of
  /// its body). Plugins request fields here, never on one set's Particles directly.
  int request_field(const FieldInfo& info, int only = -1);
  /// The deformation gradient F (Particles::request_deformation_gradient) in every set.
  int request_deformation_gradient();
  /// Total particle count over all sets.
  size_t num_particles() const;
  /// Index of a set by name, or -1.
  int set_index(const std::string& name) const;
  /// The set of a body (index in the config's body list), and its particles.
  int body_set(int body) const { return body_set_[size_t(body)]; }
  Particles<D>& particles_of_body(int body) { return sets[size_t(body_set(body))].particles; }
  const Particles<D>& particles_of_body(int body) const {
    return sets[size_t(body_set(body))].particles;
  }
  /// The particles of a body that waits for a stage to activate it (`active: false`), kept
  /// outside its set until then; empty for a body in the run.
  const Particles<D>& waiting_particles(int body) const {
    static const Particles<D> none;
    return size_t(body) < inactive_.size() ? inactive_[size_t(body)] : none;
  }
  /// The set a plugin names with `key` (absent: the scheme's first set), or -1 after a located
  /// "unknown set" error listing the sets.
  int set_param(const Params& p, const std::string& key, Diagnostics& diag) const;

  // --------------------------------------------------------- sources and sinks
  /// Create particles of a body at positions x with velocity v, in its set, with fresh ids
  /// (never reused), initialised like the particles generated at t = 0 (volume and mass from the
  /// body's spacing and density, then the shape function's, the scheme's and the material's
  /// initialisation); counted in mass_created. The set is re-sorted before the next scatter.
  /// Under mpirun every rank passes the same x (a source decides from its own state and from
  /// reductions over the ranks): each keeps the points of its own cells, and the k-th point of
  /// x gets the id next + k on whichever rank keeps it, as serially.
  void add_particles(int body, const std::vector<Vec>& x, const Vec& v);
  /// The id the next created particle gets (checkpoints keep it).
  uint32_t& next_particle_id() { return next_id_; }
  /// Particle counts and masses that sources and sinks moved across the run's boundary: the mass
  /// balance mass now + mass_removed - mass_created - initial_mass is round-off (the `mass`
  /// field: the whole mass in one-phase schemes, the solid mass in two-phase ones).
  size_t created = 0, removed = 0;
  double mass_created = 0, mass_removed = 0, initial_mass = 0;
  double total_mass() const;

  // --------------------------------------------------------- stages (stages.cpp)
  /// Begin stage k: its plugins replace the running ones (swap_stage_plugins), then bodies are
  /// activated and deactivated, material states of a new model initialised, and resets done.
  void begin_stage(int k);
  /// Only the plugin exchange of stage k (what a run resumed within stage k redoes for the
  /// stages 0..k, whose particle changes the checkpoint holds already).
  void swap_stage_plugins(int k);
  /// Whether a body's particles are in the run (bodies[].active, then stages).
  bool body_active(int body) const { return active_[size_t(body)] != 0; }

  // --------------------------------------------------------- the loop
  /// One explicit step of length dt, as the runner and the tests take it: particle loads, the
  /// shape function's per-step update, the scheme's step, time and step count, the stability
  /// check of every set (every numerics.check_every steps, or now with `check`), the partition
  /// of every set. Returns false, with Simulation::failure saying why, if the run cannot go on.
  bool advance(double dt, bool check = false);
  double stable_dt() const;
  /// The largest P-wave speed of the particles' materials (m/s), as the CFL step uses it.
  double wave_speed() const;
  /// Material m's wave speed over the particles of `set` (0 if it has none), over all ranks
  /// (MAX): a material's speed may depend on its particles (the lowest density), and a scheme
  /// that scales it per particle (the two-phase fast wave) must see the whole model's. Every
  /// rank calls it, in the same order.
  double material_wave_speed(const ParticleSet<D>& set, size_t m) const {
    const double c = rank_wave_speed(set, m);
    return ranks->distributed() ? ranks->max(c) : c;
  }
  /// Material m's wave speed over this rank's particles of `set` (0 if it has none).
  double rank_wave_speed(const ParticleSet<D>& set, size_t m) const {
    const auto& r = set.partition.material_ranges[m];
    return r.end > r.begin ? materials[m]->wave_speed(set.particles, r.begin, r.end) : 0.0;
  }
  long checked_step = -1;  // the last step whose particles passed the stability check
  /// With track_motion (a stage until: static), each checked step also measures how fast the
  /// particles actually move: motion_speed = max |x^{n+1} - x^n| / dt over every set. Under FLIP
  /// the particle velocities carry a component the grid cannot see (more particles than nodes):
  /// it neither moves the particles nor decays under nodal damping, so the largest particle
  /// velocity is no measure of rest (docs/stages.md).
  bool track_motion = false;
  double motion_speed = 0;
  /// Zero and refill particle external forces from loads (only if a load uses them).
  void prepare_particle_loads();
  /// sum f . x over the particles' external forces and positions (this rank's): its change over
  /// a step is the particle loads' work on the particles' moves.
  double particle_load_moment() const;
  /// The energy particles [begin, end) of P (those with only[i] != 0, if given) bring into the
  /// run (sign 1: created, activated) or take out of it (-1: removed), into ledger.totals.
  void carry_energy(const Particles<D>& P, size_t begin, size_t end, double sign,
                    const uint8_t* only = nullptr);
  /// Re-sort the particles of every set now.
  void sort();
  void sort(ParticleSet<D>& set);
  /// After a step: keep every set's partition valid and sort periodically.
  void maintain_partition();
  /// Kinetic, stored and gravity energy and momentum of every particle set and phase: the
  /// particles' own (mass, velocity), the materials' strain energy, and the scheme's share
  /// (Scheme::add_energies: e.g. the pore water of a two-phase scheme).
  Energies energies() const;

  /// Ids of the particles of `set` inside a named selection box (`selections:`). Returns false
  /// if no selection has that name.
  bool selection(const std::string& name, const ParticleSet<D>& set,
                 std::vector<uint32_t>& ids) const;
  /// Index of the body `name` in the config's `bodies:` (the order of Simulation::bodies), or -1.
  int body_index(const std::string& name) const;
  /// A located "unknown body 'name'; bodies are: ..." error.
  void unknown_body(Diagnostics& diag, const Location& where, const std::string& path,
                    const std::string& name) const;
  /// Make the current positions of particles [begin, end) of P their displacement reference
  /// (initial_position, when the output or a reference requested it).
  void restart_displacement(Particles<D>& P, size_t begin, size_t end) const;
  /// Copy `components` columns of field `from` into field `to` for particles [begin, end).
  static void copy_columns(Particles<D>& P, int from, int to, int components, size_t begin,
                           size_t end);
  /// The displacement reference `initial_position` of every set (the output's displacement, a
  /// stage's reset: [displacement], a reference that measures a failed mass): requested once,
  /// and set to the current positions when it is new. Returns its field handle.
  int request_displacement_reference();
  /// The reference of the strain output (strain_magnitude): the deformation gradient F is
  /// requested, and its value at the last displacement reset kept as reset_deformation_gradient
  /// (the identity at t = 0). Returns that field's handle.
  int request_strain_reference();
  /// The body a plugin names with `key` (the first body when the key is absent), or -1 after a
  /// located "unknown body" error listing the bodies.
  /// With need_particles (loads, references), a body that starts empty (no generator) is an
  /// error too; a source names such a body.
  int body_param(const Params& p, const std::string& key, Diagnostics& diag,
                 bool need_particles = true) const;

  /// First particle whose position, velocity or stress is not finite, or that left the grid:
  /// returns false and fills a description.
  bool check_particles(std::string& what) const;
  bool check_particles(const ParticleSet<D>& set, std::string& what) const;

 private:
  void build_grid(const Params& g, Diagnostics& diag);
  void read_settings();
  /// Refuse a run whose stable time step at the start needs more than time.max_steps steps,
  /// and warn of one that needs implausibly many (a unit slip).
  void check_step_budget(Diagnostics& diag);
  /// Under mpirun: refuse what does not run on ranks yet, and store this rank's box of nodes.
  void split_over_ranks(Diagnostics& diag);
  /// After the move under mpirun: hand the particles over to the ranks owning their cells.
  void migrate_particles();
  void generate_bodies(Diagnostics& diag);
  struct GeneratedPoints;  // the lattice points of every body (simulation_build.cpp)
  bool generate_points(GeneratedPoints& pts, Diagnostics& diag);
  void fill_sets(const GeneratedPoints& pts);
  void set_initial_velocity_and_stress(const GeneratedPoints& pts);
  void initialize_fields(Diagnostics& diag);  // bodies[].initial
  void create_plugins(Diagnostics& diag);
  void create_sets(Diagnostics& diag);
  void apply_sinks();
  /// After a step: sinks remove, then sources create (at the new time).
  void exchange_particles();
  void check_sources_and_sinks(Diagnostics& diag);
  void create_stages(Diagnostics& diag);
  /// Set up the stages' plugins of one kind, at the point of the build where the running ones
  /// of that kind are set up (what: "materials", "boundaries", "loads").
  void setup_stage_plugins(const char* what, Diagnostics& diag);
  /// Move the particles of bodies with `active: false` out of their sets (into inactive_).
  void keep_inactive_bodies_aside();
  std::vector<Particles<D>> inactive_;          // per body: its particles before it is activated
  std::vector<std::vector<double>> motion_x0_;  // per set: positions before a tracked step
  void keep_positions();
  double largest_move(double step_dt) const;
  std::vector<char> active_;  // per body
  uint32_t next_id_ = 0;
  std::vector<int> body_set_;  // per config body, its set (0 after an error)
  std::vector<std::pair<std::string, std::pair<Vec, Vec>>> selections_;
  mutable std::array<HeldComponents, 2> held_;  // per phase, scratch of constrain_update
};

}  // namespace loam
