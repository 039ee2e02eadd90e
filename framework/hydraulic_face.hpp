#pragma once
// Base of the hydraulic face conditions of two-phase schemes (drained, impermeable,
// prescribed_pore_pressure): they act on the pore water (grid phase 1) after every mechanical
// condition (Simulation::constrain_update), one of them per face.
//
// In the v-w formulation the pore pressure lives on the particles and the water's weak form
// leaves p = 0 as the natural condition wherever the water velocity is free. A mechanical
// condition with `phase: both` (the default of fixed and slip) holds the water too, so its face
// is impermeable; `drained` and `prescribed_pore_pressure` release the water on their face
// again: they record its unconstrained update before the mechanical conditions run and restore
// it afterwards, so a fixed, drained base is written simply as fixed + drained. The restored
// water was solved against the skeleton's free velocity; the scheme then solves it again against
// the held skeleton (the drag re-solve of a free phase next to a held one, e.g.
// two_phase_single_point's follow_held_phase), so the released water is not dragged by a
// skeleton velocity that the face does not allow.
#include <string>
#include <vector>

#include "boundary.hpp"
#include "diagnostics.hpp"
#include "params.hpp"
#include "simulation.hpp"

namespace loam {

template <int D>
class HydraulicFace : public Boundary<D> {
 public:
  explicit HydraulicFace(const Params& p) : params_(p), face_(parse_face(p.text("face"))) {}
  static void add_face(Schema& s) { s.choice("face", face_names(), "grid face").required(); }

  bool hydraulic() const override { return true; }
  bool applies_to(int phase) const override { return phase == 1; }
  /// The condition's YAML name, for the one-condition-per-face error.
  virtual const char* condition() const = 0;

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(face_, D, params_, "face", diag)) return;
    if (sim.scheme->phases() < 2) {
      diag.error(params_.where(), params_.path(),
                 std::string("'") + condition() +
                     "' is a hydraulic condition on the pore water: it needs a two-phase scheme "
                     "(this scheme has one phase on the grid)");
      return;
    }
    for (const auto& b : sim.boundaries) {
      if (b.get() == this) break;
      const auto* h = dynamic_cast<const HydraulicFace<D>*>(b.get());
      if (h && h->face_.axis == face_.axis && h->face_.upper == face_.upper)
        diag.error(params_.where("face"), params_.path("face"),
                   "face " + params_.text("face") + " already has the hydraulic condition '" +
                       h->condition() + "' (" + h->params_.path() + "); a face is " +
                       "drained, impermeable or at a prescribed pore pressure: one of them");
    }
    nodes_ = face_nodes(sim.grid, face_);
    area_ = face_node_areas(sim.grid, face_, nodes_);
  }

 protected:
  /// Record the water's velocity and acceleration on the face before the mechanical conditions.
  void record(const GridUpdate& u) {
    if (u.count < 2) return;
    saved_v_.resize(nodes_.size() * D);
    saved_a_.resize(nodes_.size() * D);
    for (size_t k = 0; k < nodes_.size(); ++k)
      for (int d = 0; d < D; ++d) {
        saved_v_[k * D + size_t(d)] = u.phases[1].velocity.at(nodes_[k], d);
        saved_a_[k * D + size_t(d)] = u.phases[1].acceleration.at(nodes_[k], d);
      }
  }
  /// Give the water on the face its recorded (unconstrained) update back.
  void release(const GridUpdate& u) const {
    if (u.count < 2 || saved_v_.size() != nodes_.size() * D) return;
    for (size_t k = 0; k < nodes_.size(); ++k)
      for (int d = 0; d < D; ++d) {
        u.phases[1].velocity.at(nodes_[k], d) = saved_v_[k * D + size_t(d)];
        u.phases[1].acceleration.at(nodes_[k], d) = saved_a_[k * D + size_t(d)];
      }
  }
  /// The same for a single nodal vector of the water (MUSL re-mapped velocities).
  void record(const NodalVector& v) {
    saved_r_.resize(nodes_.size() * D);
    for (size_t k = 0; k < nodes_.size(); ++k)
      for (int d = 0; d < D; ++d) saved_r_[k * D + size_t(d)] = v.at(nodes_[k], d);
  }
  void release(const NodalVector& v) const {
    if (saved_r_.size() != nodes_.size() * D) return;
    for (size_t k = 0; k < nodes_.size(); ++k)
      for (int d = 0; d < D; ++d) v.at(nodes_[k], d) = saved_r_[k * D + size_t(d)];
  }

  Params params_;
  Face face_;
  std::vector<size_t> nodes_;
  std::vector<double> area_;  // tributary face area per node (m^(D-1))

 private:
  std::vector<double> saved_v_, saved_a_, saved_r_;
};

}  // namespace loam
