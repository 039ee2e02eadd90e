// Slip (roller) grid face: the normal velocity component is zero, tangential motion is free.
// `directions` fixes other components instead (slip per direction).
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
    s.choice("face", face_names(), "grid face").required();
    s.string_list("directions", "components to fix (x, y, z); default: the face normal");
    return s;
  }
  explicit Slip(const Params& p) : params_(p), face_(parse_face(p.text("face"))) {}
  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(face_, D, params_, "face", diag)) return;
    nodes_ = face_nodes(sim.grid, face_);
    if (!params_.has("directions")) {
      fixed_.push_back(face_.axis);
      return;
    }
    for (const auto& c : params_.strings("directions")) {
      int axis = c.size() == 1 ? c[0] - 'x' : -1;
      if (axis < 0 || axis >= D)
        diag.error(params_.where("directions"), params_.path("directions"),
                   "unknown direction '" + c + "' (use x" + (D > 1 ? ", y" : "") +
                       (D > 2 ? ", z" : "") + ")");
      else
        fixed_.push_back(axis);
    }
  }
  void constrain(const NodalVector& v) const override {
    for (size_t n : nodes_)
      for (int d : fixed_) v.at(n, d) = 0.0;
  }

 private:
  Params params_;
  Face face_;
  std::vector<size_t> nodes_;
  std::vector<int> fixed_;
};

LOAM_REGISTER(Boundary, Slip)

}  // namespace loam
