// Surface traction (Pa) on the particles of a body face or of a named particle set. Each
// particle carries the force t * A_p, with A_p = V_p / s the particle's share of the face
// (s: particle spacing normal to the face, both at the start: a nominal traction), scaled by
// its time function (framework/load_time.hpp; or ramped linearly from 0 over ramp_time).
//
// apply_at: particle (default) adds the force to the particle, so it reaches the nodes with the
// particle's own weights, i.e. at the particle centre, half a particle below the real surface.
// Under large compression that misplaces the load: the top particle's cell then balances the
// load with the wrong share of the cell, and the surface particle is over- or under-stressed
// (1D soft column: -25 kPa instead of -50 kPa with CPDI). apply_at: surface adds
// t A_p N_I(x_s) to the nodal forces at the particle's surface point, the centre of its loaded
// face convected with the deformation gradient F (requested for this), as CPDI convects its
// domains: x_s = x_p + F (s/2) N, N the outward face normal in the reference configuration and
// s the particle spacing along it. Under simple shear the point moves tangentially by s gamma/2
// and under a rotation it turns with the particle (not only x_p + (s F_nn/2) N along a fixed
// axis, which ignores both). The tent functions N_I are the grid basis of
// linear, GIMP and CPDI, and for B-splines a distribution with the same resultant and moment.
// It needs a shape function whose stencil covers the particle domain (not `linear`), otherwise
// the surface node may carry no mass and the load would be lost.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "framework/load_time.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Traction : public Load<D> {
 public:
  static constexpr const char* name = "traction";
  static constexpr const char* summary =
      "traction on a body face or a selection of particles, with a time ramp";
  static Schema schema() {
    Schema s;
    s.text("body", "body whose face is loaded");
    s.text("selection",
           "a named selection (`selections:`) to load instead of a body face: one particle "
           "layer deep along the face normal (each selected particle carries t A_p; a deeper "
           "selection is an error)");
    s.text("set", "with `selection`: the particle set it selects from (default: the first)");
    s.choice("face", face_names(), "face (of the body) the traction acts on; sets the loaded area")
        .required();
    s.vector("traction", "Pa", "traction vector (force per unit area)").required();
    add_load_time_keys(s);
    s.choice("apply_at", {"particle", "surface"},
             "particle: the force acts at the particle centre (particle weights); surface: at "
             "the particle's current surface point x_p + F (s/2) N (the centre of its loaded face "
             "convected with the deformation gradient F), with the grid tent functions (exact "
             "load position under large strain, shear and rotation; needs gimp, cpdi or "
             "bspline2)")
        .def("particle");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.has("body") == p.has("selection"))
        d.error(p.where(), p.path(), "give exactly one of 'body' or 'selection'");
      if (p.has("body") && p.has("set"))
        d.error(p.where("set"), p.path("set"), "a body's particles are in the body's set");
    });
    return s;
  }
  explicit Traction(const Params& p)
      : params_(p),
        face_(parse_face(p.text("face"))),
        time_(p),
        surface_(p.text("apply_at") == "surface") {
    for (int d = 0; d < D; ++d) t_[size_t(d)] = p.vec("traction")[size_t(d)];
  }
  bool uses_particle_forces() const override { return !surface_; }
  bool uses_grid_forces() const override { return surface_; }
  /// Applied as particle forces (scattered before the nodal sums are completed), each rank
  /// holding every loaded particle's id and area, so a particle that changes rank keeps its
  /// load. At the surface: each rank adds its own particles' surface forces to a nodal array
  /// that is completed over the ranks (one more halo exchange per step) before it joins the
  /// nodal forces.
  bool runs_on_ranks() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(face_, D, params_, "face", diag)) return;
    if (params_.has("selection")) {
      set_ = sim.set_param(params_, "set", diag);
      if (set_ < 0) return;
      if (!sim.selection(params_.text("selection"), sim.sets[size_t(set_)], ids_)) {
        diag.error(params_.where("selection"), params_.path("selection"),
                   "unknown selection '" + params_.text("selection") + "'");
        return;
      }
    } else {
      const int b = sim.body_param(params_, "body", diag);
      if (b < 0) return;
      set_ = sim.body_set(b);
      const Body& body = sim.bodies[size_t(b)];
      const auto& P = sim.sets[size_t(set_)].particles;
      const double plane =
          face_.upper ? body.upper[size_t(face_.axis)] : body.lower[size_t(face_.axis)];
      const double half = 0.5 * body.spacing[size_t(face_.axis)];
      for (size_t i = 0; i < P.size(); ++i)
        if (P.body[i] == b && std::fabs(P.col(P.position, face_.axis)[i] - plane) < half * 1.001)
          ids_.push_back(P.id[i]);
    }
    if (params_.has("selection")) check_one_layer(sim, diag);
    area_.resize(ids_.size());
    length_.resize(ids_.size());
    const auto& set = sim.sets[size_t(set_)];
    const auto& P = set.particles;
    for (size_t k = 0; k < ids_.size(); ++k) {
      size_t i = set.index_of(ids_[k]);
      length_[k] = sim.bodies[P.body[i]].spacing[size_t(face_.axis)];
      area_[k] = P.col(P.volume)[i] / length_[k];
    }
    gather_over_ranks(*sim.ranks);
    if (ids_.empty())
      diag.error(params_.where(), params_.path(), "the traction selects no particles");
    if (surface_) {
      if (!sim.shape->stencil_covers_domain())
        diag.error(params_.where("apply_at"), params_.path("apply_at"),
                   "apply_at: surface needs a shape function whose stencil covers the particle "
                   "domain (gimp, cpdi, bspline2); with this one the surface node may have no "
                   "mass and the load would be lost");
      F_ = sim.request_deformation_gradient();
    }
  }

  void apply_to_grid(Simulation<D>& sim, const NodalVector& force, double t) override {
    if (!surface_) return;
    // One rank (serially, or mpirun -np 1) adds them directly: the serial run's bits.
    if (sim.ranks->size() == 1) return add_surface_forces(sim, force, t);
    const size_t n = sim.grid.num_nodes;
    surface_force_.assign(n * D, 0.0);
    add_surface_forces(sim, NodalVector{surface_force_.data(), D, 0}, t);
    sim.complete_nodes({{surface_force_.data(), D, D}});  // every rank calls it, every step
    for (size_t i = 0; i < n; ++i)
      for (int d = 0; d < D; ++d) force.at(i, d) += surface_force_[i * D + size_t(d)];
  }

  void apply_to_particles(Simulation<D>& sim, double t) override {
    if (surface_) return;
    const double s = time_(t);
    sim.add_external_forces(set_, ids_,
                            [&](size_t k, int d) { return s * t_[size_t(d)] * area_[k]; });
  }

 private:
  /// t A_p N_I(x_s) of this rank's loaded particles, added to `force`.
  void add_surface_forces(Simulation<D>& sim, const NodalVector& force, double t) const {
    const double s = time_(t);
    const auto& set = sim.sets[size_t(set_)];
    const auto& P = set.particles;
    const Grid<D>& g = sim.grid;
    const int a = face_.axis;
    for (size_t k = 0; k < ids_.size(); ++k) {
      const size_t i = set.index_of(ids_[k]);
      if (i == set.npos) continue;  // not in the run (its body waits for a stage)
      // Surface point x_p + F (s/2) N (N = +-e_a, so F N is column a of F) and its cell: per
      // axis the lower node and the tent weight of the upper.
      const double half = (face_.upper ? 0.5 : -0.5) * length_[k];
      std::array<int, D> cell{};
      std::array<double, D> frac{};
      for (int d = 0; d < D; ++d) {
        const double x = P.col(P.position, d)[i] + half * P.col(F_, d * D + a)[i];
        const int c = g.cell_of(x, d);
        frac[size_t(d)] =
            std::clamp((x - g.origin[size_t(d)]) * g.inv_cell[size_t(d)] - c, 0.0, 1.0);
        cell[size_t(d)] = c;
      }
      for (int corner = 0; corner < (1 << D); ++corner) {
        double w = 1;
        std::array<int, D> ijk = cell;
        for (int d = 0; d < D; ++d) {
          const bool up = (corner >> d) & 1;
          w *= up ? frac[size_t(d)] : 1 - frac[size_t(d)];
          ijk[size_t(d)] += up ? 1 : 0;
        }
        const size_t node = g.node_index(ijk);
        for (int d = 0; d < D; ++d) force.at(node, d) += w * s * t_[size_t(d)] * area_[k];
      }
    }
  }

  /// Under mpirun: every rank's loaded particles (id, area, length) on every rank, in rank
  /// order (docs/parallel.md).
  void gather_over_ranks(const Ranks<D>& ranks) {
    if (!ranks.distributed()) return;
    std::vector<double> mine;
    for (size_t k = 0; k < ids_.size(); ++k)
      mine.insert(mine.end(), {double(ids_[k]), area_[k], length_[k]});
    const std::vector<double> all = ranks.all_gather(mine);
    ids_.clear(), area_.clear(), length_.clear();
    for (size_t k = 0; k + 2 < all.size(); k += 3) {
      ids_.push_back(uint32_t(all[k]));
      area_.push_back(all[k + 1]);
      length_.push_back(all[k + 2]);
    }
  }

  /// Each selected particle carries t A_p: a selection two particles deep along the face normal
  /// would carry the traction twice. Particles on one line normal to the face share their
  /// tangential lattice cell (floor(x / spacing) on every other axis, at set-up). On a split
  /// grid the lines are gathered from every rank (a second layer may be on another rank).
  void check_one_layer(const Simulation<D>& sim, Diagnostics& diag) const {
    const auto& set = sim.sets[size_t(set_)];
    const auto& P = set.particles;
    std::vector<double> mine;  // per selected particle: its tangential cell, then its coordinate
    for (uint32_t id : ids_) {
      const size_t i = set.index_of(id);
      const auto& spacing = sim.bodies[P.body[i]].spacing;
      for (int d = 0; d < D; ++d)
        mine.push_back(d == face_.axis ? 0.0
                                       : std::floor(P.col(P.position, d)[i] / spacing[size_t(d)]));
      mine.push_back(P.col(P.position, face_.axis)[i]);
    }
    // Unsplit (a refused run) every rank holds every particle: its own list is the whole one.
    const std::vector<double> all = sim.ranks->split() ? sim.ranks->all_gather(mine) : mine;
    std::map<std::array<long, D>, double> line;  // tangential cell -> the first one's coordinate
    for (size_t k = 0; k + D < all.size(); k += D + 1) {
      std::array<long, D> key{};
      for (int d = 0; d < D; ++d) key[size_t(d)] = long(all[k + size_t(d)]);
      const double b = all[k + D];
      const auto [it, first] = line.emplace(key, b);
      if (first) continue;
      const char* axes = "xyz";
      const double a = it->second;
      diag.error(params_.where("selection"), params_.path("selection"),
                 "selection '" + params_.text("selection") +
                     "' is more than one particle layer deep along the face normal (particles "
                     "at " +
                     axes[face_.axis] + " = " + format_number(std::min(a, b)) + " and " +
                     format_number(std::max(a, b)) +
                     " m on one line): a traction loads every selected particle with t A_p, "
                     "so the load would be multiplied; select only the surface layer");
      return;
    }
  }

  Params params_;
  Face face_;
  LoadTime<D> time_;
  bool surface_;
  int F_ = -1;
  int set_ = 0;                 // the set of the loaded particles
  std::vector<double> length_;  // particle spacing normal to the face (reference length)
  std::array<double, D> t_{};
  std::vector<uint32_t> ids_;
  std::vector<double> area_;
  std::vector<double> surface_force_;  // under mpirun: this rank's surface forces, per node
};

LOAM_REGISTER(Load, Traction)

}  // namespace loam
