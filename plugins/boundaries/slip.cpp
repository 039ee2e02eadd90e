// Slip (roller) grid face: the normal velocity component is zero, tangential motion is free.
// `directions` fixes other components instead (slip per direction). The held components are
// marked (mark_held): a friction face meeting this one at an edge slides only in the others.
// With `min` and `max` instead of `face` it acts on every node of that box inside the grid, with
// the components named in `directions`: a smooth structure, e.g. a sheet pile the pore water
// flows along (phase: water, directions: [x]: impermeable across it, free along it, as Darcy
// flow past a wall is; a no-slip `fixed` box would also stop the flow along it, widening the
// pile by a cell on each side). A box holds its nodes only, not the particles.
#include <algorithm>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Slip : public Boundary<D> {
 public:
  static constexpr const char* name = "slip";
  static constexpr const char* summary =
      "roller grid face: normal velocity zero (or chosen components)";
  static Schema schema() {
    Schema s;
    add_reaction_name(s);
    add_face_or_box_params(s, /*face_required_otherwise=*/true);
    add_phase_param(s);
    s.string_list("directions",
                  "components to fix (x, y, z); default: the face normal (required with a box)");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.has("min") && !p.has("directions"))
        d.error(p.where(), p.path(), "a box has no normal: give directions (e.g. [x])");
    });
    return s;
  }
  explicit Slip(const Params& p)
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
    face_or_box_components(sim.grid, params_, face_, box_, nodes_, fixed_, diag);
  }
  void constrain(const NodalVector& v) const override {
    for (size_t n : nodes_)
      for (int d : fixed_) v.at(n, d) = 0.0;
  }
  void mark_held(HeldComponents& held) const override { hold_components(held, nodes_, fixed_); }
  /// Only if the solid's normal is among the fixed directions (`directions: [y]` on x- holds a
  /// tangential component: the particles may leave through x-).
  int holds_face(int phase) const override {
    const bool normal = std::find(fixed_.begin(), fixed_.end(), face_.axis) != fixed_.end();
    return normal && applies_to(phase) && !box_ ? face_index(face_) : -1;
  }

  const std::vector<size_t>* reaction_nodes() const override { return &nodes_; }

 private:
  Params params_;
  Face face_;
  bool box_;
  int phases_;  // bit 0 solid, bit 1 water
  std::vector<size_t> nodes_;
  std::vector<int> fixed_;
};

LOAM_REGISTER(Boundary, Slip)

}  // namespace loam
