// Reference: the bearing capacity of a footing on undrained (Tresca) clay, measured from the
// reaction of the condition that pushes it (a rigid_body, docs/contact.md) and compared with
// Prandtl's q_u = N_c s_u, N_c = 2 + pi for a strip on weightless clay (Prandtl 1920, "Über die
// Härte plastischer Körper"; smooth and rough alike). The pressure is the reaction along the
// last axis over the width it carries,
//   q = -R / b    (b: the footing's width in the model; the half width in a half model),
// averaged over the steps whose time lies in `window` (the plateau of the load-settlement
// curve; for a footing pushed at speed v from t = 0 the settlements [v t0, v t1]). An
// embedment D changes N_c: Skempton's (1951) depth factor (1 + 0.2 D / B) at the window's mean
// settlement is the usual correction (docs/verification.md A), given here through
// bearing_factor. Metrics: bearing_pressure (Pa), bearing_ratio q / s_u, bearing_error
// q / (N_c s_u) - 1, bearing_samples (steps averaged).
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class BearingCapacity : public Reference<D> {
 public:
  static constexpr const char* name = "bearing_capacity";
  static constexpr const char* summary =
      "bearing pressure -R / b of a pushed footing from a condition's reaction, averaged over a "
      "time window, against N_c s_u (Prandtl's 2 + pi)";
  static Schema schema() {
    Schema s;
    s.text("reaction", "the reaction's name (the condition's `name:`) that pushes the footing")
        .required();
    s.real("width", "m",
           "the footing width b the reaction carries per unit length (2D) or the footing's area "
           "(3D, m^2); the half width in a half model")
        .required()
        .positive();
    s.real("undrained_strength", "Pa", "the clay's undrained shear strength s_u (Tresca c)")
        .required()
        .positive();
    s.real("bearing_factor", "-",
           "N_c of the reference q_u = N_c s_u: 2 + pi for a strip at the surface (Prandtl); "
           "times Skempton's (1 + 0.2 D / B) for an embedment D")
        .def("5.141592653589793")
        .positive();
    s.real_list("window", "s",
                "[t0, t1]: the times whose steps the pressure is averaged over (the plateau)")
        .required();
    return s;
  }
  explicit BearingCapacity(const Params& p) : params_(p), width_(p.real("width")) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    const auto& w = params_.vec("window");
    if (w.size() != 2 || !(w[0] >= 0 && w[1] > w[0]))
      diag.error(params_.where("window"), params_.path("window"),
                 "give [t0, t1] with 0 <= t0 < t1");
    else
      t0_ = w[0], t1_ = w[1];
    const std::string wanted = params_.text("reaction");
    const auto& names = sim.reactions.names();
    for (size_t k = 0; k < names.size(); ++k)
      if (names[k] == wanted) slot_ = long(k);
    if (slot_ < 0) {
      std::string known;
      for (const auto& n : names) known += (known.empty() ? "" : ", ") + n;
      diag.error(params_.where("reaction"), params_.path("reaction"),
                 "no reaction named '" + wanted +
                     "' (the conditions' reactions: " + (known.empty() ? "none" : known) + ")");
    }
  }

  void sample(Simulation<D>& sim) override {
    if (slot_ < 0 || sim.time < t0_ || sim.time > t1_) return;
    sum_ += -sim.reactions.force(size_t(slot_))[D - 1] / width_;
    count_ += 1;
  }

  std::map<std::string, double> metrics(Simulation<D>&) override {
    std::map<std::string, double> m;
    m["bearing_samples"] = count_;
    if (count_ == 0) return m;
    const double q = sum_ / count_, su = params_.real("undrained_strength");
    m["bearing_pressure"] = q;
    m["bearing_ratio"] = q / su;
    m["bearing_factor"] = params_.real("bearing_factor");
    m["bearing_error"] = q / (m["bearing_factor"] * su) - 1;
    return m;
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"bearing_ratio", "bearing_factor", "the bearing_factor given"}};
  }

  /// The reactions are complete over the ranks at every step (framework/reactions.hpp).
  bool runs_on_ranks() const override { return true; }
  bool save_state(std::vector<double>& s) const override {
    s = {sum_, count_};
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    if (s.size() == 2) sum_ = s[0], count_ = s[1];
  }

 private:
  Params params_;
  double width_;  // b
  long slot_ = -1;
  double t0_ = 0, t1_ = 0;
  double sum_ = 0, count_ = 0;
};

LOAM_REGISTER(Reference, BearingCapacity)

}  // namespace loam
