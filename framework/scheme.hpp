#pragma once
// Scheme plugin interface: a scheme owns the order of one explicit step (which quantities go to
// the grid, how the grid is integrated, what comes back), using the framework's building blocks
// (stencils, partitioned block loops, boundary/load/damping hooks, material batches). Every
// particle move goes through Simulation::held_faces.moved, so no particle crosses a held face.
#include <limits>
#include <string>
#include <vector>

#include "energies.hpp"
#include "params.hpp"
#include "particle_set.hpp"

namespace loam {

template <int D>
class Simulation;
class Diagnostics;

struct GridFieldView {
  std::string name;
  int components;
  const double* base;  // base[n*stride + offset + c]
  int stride, offset;
};

template <int D>
class Scheme {
 public:
  static constexpr const char* kind = "scheme";
  virtual ~Scheme() = default;
  /// The particle sets the scheme works with, in order; the first is the default of a body's
  /// `set:`. Known before set-up (the Simulation creates the sets from it).
  virtual std::vector<SetDeclaration> particle_sets() const {
    return {{"particles", "the material points"}};
  }
  /// Request particle fields and allocate node storage.
  virtual void setup(Simulation<D>&, Diagnostics&) = 0;
  /// Initialise the scheme's fields of particles [begin, end) of a set: every particle at
  /// set-up, and particles a source adds later (Simulation::add_particles).
  virtual void initialize_particles(Simulation<D>&, ParticleSet<D>&, size_t /*begin*/,
                                    size_t /*end*/) {}
  /// Called once the initial fields (bodies[].stress, bodies[].initial) and the materials'
  /// states are set, before the first frame: e.g. to derive output fields from them.
  virtual void initial_state(Simulation<D>&) {}
  /// A time-step limit of the scheme's own (e.g. explicit drag), on top of the CFL limit.
  virtual double stable_dt(const Simulation<D>&) const {
    return std::numeric_limits<double>::infinity();
  }
  virtual void step(Simulation<D>&, double dt) = 0;
  /// Particle velocity fields besides `velocity` (e.g. the pore water's of a single-point
  /// two-phase scheme, APIC's affine matrices): a stage's `reset: [velocity]` zeroes them too.
  virtual std::vector<std::string> velocity_fields() const { return {}; }
  /// Phases on the grid: 1, or 2 for a scheme with a pore-water phase (boundary phase 1).
  virtual int phases() const { return 1; }
  /// Add the energies and momentum of what the scheme carries beyond the particles' mass and
  /// velocity (a second phase, a stored fluid energy) to `e`, so that the total of a run is
  /// complete (Simulation::energies).
  virtual void add_energies(const Simulation<D>&, Energies&) const {}
  /// Nodal fields for optional grid output.
  virtual std::vector<GridFieldView> grid_fields() const { return {}; }
  /// Whether it runs on a grid split over MPI ranks (docs/parallel.md): it reads and writes only
  /// the particles of this rank and the stored box of nodes, each node as the whole grid's
  /// value. Default false: a run under mpirun refuses it with a located error.
  virtual bool runs_on_ranks() const { return false; }
  /// Whether it gives each body in contact its own velocity field (`contact:`,
  /// framework/contact_fields.hpp). Default false: `contact:` is refused with a located error.
  virtual bool supports_contact() const { return false; }
};

/// The `flip` parameter shared by the schemes: FLIP fraction of the particle velocity update.
inline void add_flip_param(Schema& s) {
  s.real("flip", "-", "FLIP fraction of the particle velocity update (1: FLIP, 0: PIC)")
      .def("1")
      .min(0)
      .max(1);
}

/// `flip` and `transfer` of a scheme that offers the affine transfers (framework/
/// affine_transfer.hpp): apic and tpic replace the FLIP/PIC blend, so they take flip 1 only.
inline void add_transfer_params(Schema& s, const std::string& apic_note = "") {
  add_flip_param(s);
  s.choice("transfer", {"flip", "apic", "tpic"},
           "particle-grid velocity transfer: flip (the FLIP/PIC blend of `flip`), apic "
           "(affine particle-in-cell, Jiang et al. 2015: each particle carries an affine "
           "velocity matrix; no PIC dissipation, no FLIP noise) or tpic (Taylor particle-in-cell, "
           "Nakamura et al. 2023: the affine matrix is the particle's velocity gradient from the "
           "grid, no inertia tensor; angular momentum kept approximately" +
               apic_note + ")")
      .def("flip");
  s.check([](const Params& p, Diagnostics& d) {
    const std::string t = p.text("transfer");
    if (t != "flip" && p.real("flip") != 1.0)
      d.error(p.where("flip"), p.path("flip"),
              "flip blends FLIP and PIC; transfer: " + t +
                  " replaces both (remove flip or set it to 1)");
  });
}

}  // namespace loam
