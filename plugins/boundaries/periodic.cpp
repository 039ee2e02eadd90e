// Periodic grid: the two faces normal to `axis` are one. A particle leaving through one face
// enters through the other (HeldFaces::moved wraps its position by the grid's length), and each
// node of one face and its partner on the other are one node: before the grid update (the face
// forces, Boundary::add_forces) their masses, momenta and forces are summed and given to both,
// so that the damping, the update v^{n+1} = (p + dt f) / m and every other condition see the
// joined node. The MUSL re-map scatters the particles' momenta again, each face node then
// holding its side's share over the joined mass: the pair's velocity is the sum of the two.
// Use: an infinite slope or layer (docs/strength_reduction.md), a periodic shear box. Needs a
// stencil of two nodes per axis (linear: wider stencils reach beyond the faces, where the grid is
// not periodic) and a scheme that hands the conditions its nodal masses and momenta
// (GridForces::mass; single_phase with update: musl or usl).
#include "framework/diagnostics.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Periodic : public Boundary<D> {
 public:
  static constexpr const char* name = "periodic";
  static constexpr const char* summary =
      "the two grid faces normal to an axis are one (particles wrap, face nodes are shared); "
      "linear shape function";
  static Schema schema() {
    Schema s;
    s.choice("axis", {"x", "y", "z"}, "the axis along which the grid repeats").required();
    return s;
  }
  explicit Periodic(const Params& p) : params_(p), axis_(p.text("axis")[0] - 'x') {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    sim_ = &sim;
    if (axis_ >= D) {
      diag.error(params_.where("axis"), params_.path("axis"),
                 "axis " + params_.text("axis") + " does not exist in " + std::to_string(D) + "D");
      return;
    }
    if (sim.shape->max_nodes_per_particle() != (1 << D))
      diag.error(params_.where(), params_.path(),
                 "a periodic grid needs a stencil of two nodes per axis (shape_function: linear); "
                 "this one has " +
                     std::to_string(sim.shape->max_nodes_per_particle()) +
                     " nodes per particle and reaches beyond the periodic faces");
    if (sim.scheme->phases() != 1)
      diag.error(params_.where(), params_.path(),
                 "periodic supports single-phase schemes only (it joins the nodal masses and "
                 "momenta, which a two-phase scheme does not hand to the conditions yet)");
    lo_ = face_nodes(sim.grid, Face{axis_, false});
    hi_ = face_nodes(sim.grid, Face{axis_, true});
    // A face another condition holds: Simulation::check_periodic_faces (after every set-up).
  }
  int periodic_axis() const override { return axis_; }
  /// Under mpirun no block boundary cuts the axis (Ranks::decompose keeps it whole), so each
  /// rank holds both faces of its stored nodes, pairwise, and joins them after the nodal sums
  /// are complete.
  bool runs_on_ranks() const override { return true; }

  /// The join: mass, momentum and force of each pair summed into both nodes.
  void add_forces(const GridForces& g) const override {
    if (!g.mass.base) {
      sim_->failure = "periodic: the scheme gave no nodal masses to join";
      return;
    }
    for (size_t i = 0; i < lo_.size(); ++i) {
      const size_t a = lo_[i], b = hi_[i];
      g.mass.at(a, 0) = g.mass.at(b, 0) = g.mass.at(a, 0) + g.mass.at(b, 0);
      for (int d = 0; d < D; ++d) {
        g.momentum.at(a, d) = g.momentum.at(b, d) = g.momentum.at(a, d) + g.momentum.at(b, d);
        g.mixture.at(a, d) = g.mixture.at(b, d) = g.mixture.at(a, d) + g.mixture.at(b, d);
      }
    }
    joined_step_ = sim_->step;
  }
  /// The grid update acts on joined nodes already: nothing to do.
  void constrain_grid_update(const GridUpdate&) const override {}
  /// A velocity the scheme constrains alone: the MUSL re-map, after this step's join (each face
  /// node holds its side's momentum over the joined mass, so the pair's velocity is their sum).
  /// Before the join (USF) the pair's masses are not known here: the run stops with a message.
  void constrain(const NodalVector& v) const override {
    if (joined_step_ != sim_->step) {
      sim_->failure =
          "periodic: a nodal velocity was constrained before the step's nodal forces (scheme "
          "update: usf); use update: musl or usl";
      return;
    }
    for (size_t i = 0; i < lo_.size(); ++i)
      for (int d = 0; d < D; ++d)
        v.at(lo_[i], d) = v.at(hi_[i], d) = v.at(lo_[i], d) + v.at(hi_[i], d);
  }

 private:
  Params params_;
  int axis_;
  Simulation<D>* sim_ = nullptr;
  std::vector<size_t> lo_, hi_;    // the face nodes, pairwise
  mutable long joined_step_ = -1;  // the step whose nodes were joined last
};

LOAM_REGISTER(Boundary, Periodic)

}  // namespace loam
