// Surface traction (Pa) on the particles of a body face or of a named particle set. Each
// particle carries the force t * A_p, with A_p = V_p / s the particle's share of the face
// (s: particle spacing normal to the face), ramped linearly from 0 over ramp_time.
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Traction : public Load<D> {
 public:
  static constexpr const char* name = "traction";
  static constexpr const char* summary =
      "traction on a body face or particle set, with a time ramp";
  static Schema schema() {
    Schema s;
    s.text("body", "body whose face is loaded");
    s.text("set", "particle set to load instead of a body face");
    s.choice("face", face_names(), "face (of the body) the traction acts on; sets the loaded area")
        .required();
    s.vector("traction", "Pa", "traction vector (force per unit area)").required();
    s.real("ramp_time", "s", "linear ramp from 0 to full load").def("0").min(0);
    s.check([](const Params& p, Diagnostics& d) {
      if (p.has("body") == p.has("set"))
        d.error(p.where(), p.path(), "give exactly one of 'body' or 'set'");
    });
    return s;
  }
  explicit Traction(const Params& p)
      : params_(p), face_(parse_face(p.text("face"))), ramp_(p.real("ramp_time")) {
    for (int d = 0; d < D; ++d) t_[size_t(d)] = p.vec("traction")[size_t(d)];
  }
  bool uses_particle_forces() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(face_, D, params_, "face", diag)) return;
    const auto& P = sim.particles;
    if (params_.has("set")) {
      if (!sim.particle_set(params_.text("set"), ids_)) {
        diag.error(params_.where("set"), params_.path("set"),
                   "unknown particle set '" + params_.text("set") + "'");
        return;
      }
    } else {
      const int b = sim.body_param(params_, "body", diag);
      if (b < 0) return;
      const Body& body = sim.bodies[size_t(b)];
      const double plane =
          face_.upper ? body.upper[size_t(face_.axis)] : body.lower[size_t(face_.axis)];
      const double half = 0.5 * body.spacing[size_t(face_.axis)];
      for (size_t i = 0; i < P.size(); ++i)
        if (P.body[i] == b && std::fabs(P.col(P.position, face_.axis)[i] - plane) < half * 1.001)
          ids_.push_back(P.id[i]);
    }
    if (ids_.empty())
      diag.error(params_.where(), params_.path(), "the traction selects no particles");
    area_.resize(ids_.size());
    for (size_t k = 0; k < ids_.size(); ++k) {
      size_t i = sim.index_of(ids_[k]);
      area_[k] = P.col(P.volume)[i] / sim.bodies[P.body[i]].spacing[size_t(face_.axis)];
    }
  }

  void apply_to_particles(Simulation<D>& sim, double t) override {
    const double s = ramp_factor(t, ramp_);
    auto& P = sim.particles;
    for (size_t k = 0; k < ids_.size(); ++k) {
      size_t i = sim.index_of(ids_[k]);
      for (int d = 0; d < D; ++d) P.col(sim.external_force, d)[i] += s * t_[size_t(d)] * area_[k];
    }
  }

 private:
  Params params_;
  Face face_;
  double ramp_;
  std::array<double, D> t_{};
  std::vector<uint32_t> ids_;
  std::vector<double> area_;
};

LOAM_REGISTER(Load, Traction)

}  // namespace loam
