// Drained face of a two-phase scheme: the pore water passes the face freely, so the pore
// pressure there is zero (the natural condition of the water's weak form, eq. 16 of the FEM-and-MPM
// comparison of large-strain consolidation, seed 001; its copy names no title or authors,
// docs/verification.md lists it).
// It releases the water from a mechanical condition on the same face: `fixed` + `drained` is a
// fixed, drained base (a porous stone); see framework/hydraulic_face.hpp.
#include "framework/hydraulic_face.hpp"
#include "framework/registry.hpp"

namespace loam {

template <int D>
class Drained : public HydraulicFace<D> {
 public:
  static constexpr const char* name = "drained";
  static constexpr const char* summary =
      "two-phase: the pore water leaves the grid face freely (pore pressure 0 there), even if "
      "the skeleton is fixed on it";
  static Schema schema() {
    Schema s;
    HydraulicFace<D>::add_face(s);
    return s;
  }
  explicit Drained(const Params& p) : HydraulicFace<D>(p) {}
  const char* condition() const override { return name; }
  /// Per node of the face, on the stored box (docs/parallel.md).
  bool runs_on_ranks() const override { return true; }
  int releases_face() const override { return face_index(this->face_); }
  void before_constraints(const GridUpdate& u) override { this->record(u); }
  void constrain_grid_update(const GridUpdate& u) const override { this->release(u); }
  void before_constrain(const NodalVector& v, int) override { this->record(v); }
  void constrain(const NodalVector& v) const override { this->release(v); }
};

LOAM_REGISTER(Boundary, Drained)

}  // namespace loam
