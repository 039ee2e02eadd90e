// Prescribed pore pressure on a face of a two-phase scheme: p = `pressure` (Pa, compression
// positive), or p = gamma_w (head - z) from a piezometric `head` (m; z the node's coordinate
// along the last axis, the vertical). The water passes the face freely (as `drained`, which is
// the case p = 0) and the face adds the boundary term of the weak forms (eqs. 16-17 of the
// FEM-and-MPM comparison of large-strain consolidation, seed 001; its copy names no title or
// authors, docs/verification.md lists it):
// with n_out the outward normal and A_I the node's tributary face area, the mixture gets the
// total traction -p n_out A_I, of which the water equation (per unit pore volume, times the
// nodal porosity n_I) takes -n_I p n_out A_I. They are nodal forces added before the scheme
// solves the grid update (Boundary::add_forces), so the implicit drag couples them like every
// other force; a skeleton fixed on the face then stays fixed, and the released water follows
// the held skeleton through the drag (framework/hydraulic_face.hpp). A `time_function` f(t) of
// the loads' time scales the pressure, p f(t), or the head, gamma_w (head f(t) - z): a level
// that rises, falls or follows a table of levels (head: 1 and the table in metres).
#include <memory>
#include "framework/hydraulic_face.hpp"

#include "framework/load_time.hpp"
#include "framework/registry.hpp"

namespace loam {

template <int D>
class PrescribedPorePressure : public HydraulicFace<D> {
 public:
  static constexpr const char* name = "prescribed_pore_pressure";
  static constexpr const char* summary =
      "two-phase: pore pressure (or piezometric head) prescribed on a grid face; the water "
      "passes it freely";
  static Schema schema() {
    Schema s;
    HydraulicFace<D>::add_face(s);
    s.real("pressure", "Pa", "pore pressure on the face (compression positive)");
    s.real("head", "m",
           "piezometric head: p = unit_weight * (head - z), z the vertical coordinate");
    s.real("unit_weight", "N/m^3", "unit weight of the water gamma_w, for head")
        .def("9810")
        .positive();
    s.plugin("time_function", "time_function",
             "factor f(t) of the loads' time on the pressure (p f) or on the head "
             "(gamma_w (head f - z)); absent: 1");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.has("pressure") == p.has("head"))
        d.error(p.where(), p.path(), "give exactly one of 'pressure' or 'head'");
    });
    return s;
  }
  explicit PrescribedPorePressure(const Params& p)
      : HydraulicFace<D>(p),
        head_(p.has("head")),
        value_(p.has("head") ? p.real("head") : p.real("pressure")),
        unit_weight_(p.real("unit_weight")),
        f_(p) {}
  const char* condition() const override { return name; }
  int releases_face() const override { return face_index(this->face_); }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    HydraulicFace<D>::setup(sim, diag);
    z_.resize(this->nodes_.size());
    for (size_t k = 0; k < this->nodes_.size(); ++k)
      z_[k] = sim.grid.node_coord(this->nodes_[k], D - 1);
  }
  /// Per node of the face, on the stored box (docs/parallel.md): the face forces are added
  /// after the nodal sums are complete, to every stored copy of a node alike.
  bool runs_on_ranks() const override { return true; }
  bool adds_forces() const override { return true; }
  void add_forces(const GridForces& f) const override {
    if (f.count < 2 || !f.porosity.base) return;
    const int a = this->face_.axis;
    const double out = this->face_.upper ? 1.0 : -1.0;
    const double v = value_ * f_.value(f.time);
    for (size_t k = 0; k < this->nodes_.size(); ++k) {
      const size_t n = this->nodes_[k];
      const double p = head_ ? unit_weight_ * (v - z_[k]) : v;
      const double traction = -p * out * this->area_[k];
      f.mixture.at(n, a) += traction;
      f.water.at(n, a) += f.porosity.at(n, 0) * traction;
    }
  }
  /// The water's update on the face is recorded before the mechanical conditions, to be
  /// released after them.
  void before_constraints(const GridUpdate& u) override { this->record(u); }
  void constrain_grid_update(const GridUpdate& u) const override { this->release(u); }
  void before_constrain(const NodalVector& v, int) override { this->record(v); }
  void constrain(const NodalVector& v) const override { this->release(v); }

 private:
  bool head_;
  double value_;  // the pressure (Pa) or the head (m)
  double unit_weight_;
  TimeFactor<D> f_;
  std::vector<double> z_;  // per face node, its vertical coordinate (m)
};

LOAM_REGISTER(Boundary, PrescribedPorePressure)

}  // namespace loam
