// Fixed (no-slip) grid face: every velocity component of the face nodes is zero. It holds them
// all (mark_held), so a friction face sharing an edge or corner has nothing left to slide in.
// With `min` and `max` instead of `face` it holds every node inside that box of the grid: a rigid
// structure inside the model (a sheet pile, a wall, a footing), impermeable like a fixed face
// (phase: both), which the phases must flow around. Particles are kept out of a held grid face
// (Simulation::held_faces); a box inside the grid holds its nodes only, so a particle that
// reaches them stops there.
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Fixed : public Boundary<D> {
 public:
  static constexpr const char* name = "fixed";
  static constexpr const char* summary = "no-slip grid face: all velocity components zero";
  static Schema schema() {
    Schema s;
    add_reaction_name(s);
    add_face_or_box_params(s, /*face_required_otherwise=*/true);
    add_phase_param(s);
    return s;
  }
  explicit Fixed(const Params& p)
      : params_(p),
        face_(parse_face(p.has("face") ? p.text("face") : "x-")),
        box_(!p.has("face")),
        phases_(parse_phase_mask(p)) {}
  bool applies_to(int phase) const override { return (phases_ >> phase) & 1; }
  /// Per node of the stored box, on a face or a box of nodes (a rank holds its stored nodes of
  /// the box, maybe none).
  bool runs_on_ranks() const override { return true; }
  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    check_phase_mask(phases_, sim.scheme->phases(), params_, diag);
    if (box_)
      nodes_ = box_nodes(sim.grid, params_, diag);
    else if (check_face(face_, D, params_, "face", diag))
      nodes_ = face_nodes(sim.grid, face_);
  }
  void constrain(const NodalVector& v) const override {
    for (size_t n : nodes_)
      for (int d = 0; d < D; ++d) v.at(n, d) = 0.0;
  }
  void mark_held(HeldComponents& held) const override {
    for (size_t n : nodes_)
      for (int d = 0; d < D; ++d) held.hold(n, d);
  }
  /// The particles move with the solid: `phase: water` leaves them free.
  int holds_face(int phase) const override {
    return applies_to(phase) && !box_ ? face_index(face_) : -1;
  }

  const std::vector<size_t>* reaction_nodes() const override { return &nodes_; }

 private:
  Params params_;
  Face face_;
  bool box_;
  int phases_;  // bit 0 solid, bit 1 water
  std::vector<size_t> nodes_;
};

LOAM_REGISTER(Boundary, Fixed)

}  // namespace loam
