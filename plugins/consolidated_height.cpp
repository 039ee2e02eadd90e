// Reference: final height of a laterally confined elastic column consolidated under a surface
// load q (seed 001 large strain, VERIFICATION.md C "Seed 001 large strain"). Once the excess pore
// pressure has drained, the effective stress is -q everywhere (no self-weight), and the
// exact height h = J H0 follows from the stress-strain law along the column axis (nu = 0, M the
// constrained modulus):
//   jaumann (hypoelastic, Cauchy stress, Jaumann rate): sigma = M ln J   ->  J = exp(-q / M)
//   hencky  (hyperelastic, Kirchhoff stress J sigma):   J sigma = M ln J ->  ln J + (q/M) J = 0
// (q = 50 kPa, M = 100 kPa, H0 = 1 m: 0.60653 m and 0.70347 m). The measured height is the
// column's current volume over its initial cross-section, sum V_p / A0 with A0 = V0 / H0, so it
// counts the half particle beyond the outermost centres at both faces.
// Metrics (at the end of the run): final_height, exact_height, height_error (relative),
// residual_pore_pressure (max |p| / q over the body; near 0 once consolidation is complete,
// only present with a two-phase scheme) and, if given, paper_height and height_vs_paper.
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class ConsolidatedHeight : public Reference<D> {
 public:
  static constexpr const char* name = "consolidated_height";
  static constexpr const char* summary =
      "final height of a confined elastic column under a surface load, exact for the jaumann "
      "and hencky laws (large strain)";
  static Schema schema() {
    Schema s;
    s.real("load", "Pa", "surface load q (compression positive)").required().positive();
    s.real("constrained_modulus", "Pa", "M = E (1 - nu) / ((1 + nu)(1 - 2 nu)); exact for nu = 0")
        .required()
        .positive();
    s.choice("formulation", {"jaumann", "hencky"},
             "stress-strain law of the skeleton, as the material's `formulation`")
        .required();
    s.real("paper_height", "m", "a published final height to report beside (optional)").positive();
    s.text("body", "the column (default: the first body)");
    return s;
  }
  explicit ConsolidatedHeight(const Params& p)
      : params_(p),
        ratio_(p.real("load") / p.real("constrained_modulus")),
        hencky_(p.text("formulation") == "hencky") {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    H0_ = b.upper[D - 1] - b.lower[D - 1];
    V0_ = volume(sim);
    pore_ = sim.particles.find("pore_pressure");
  }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    std::map<std::string, double> m;
    const double h = volume(sim) / (V0_ / H0_), exact = H0_ * stretch();
    m["final_height"] = h;
    m["exact_height"] = exact;
    m["height_error"] = (h - exact) / exact;
    if (pore_ >= 0) {
      const auto& P = sim.particles;
      double worst = 0;
      for (size_t i = 0; i < P.size(); ++i)
        if (P.body[i] == body_) worst = std::max(worst, std::fabs(P.col(pore_)[i]));
      m["residual_pore_pressure"] = worst / params_.real("load");
    }
    if (params_.has("paper_height")) {
      m["paper_height"] = params_.real("paper_height");
      m["height_vs_paper"] = (h - m["paper_height"]) / m["paper_height"];
    }
    return m;
  }

 private:
  /// J = h / H0 of the drained column.
  double stretch() const {
    if (!hencky_) return std::exp(-ratio_);
    // ln J + r J = 0: Newton from J = 1 (the function is increasing and concave).
    double J = 1;
    for (int it = 0; it < 50; ++it) {
      const double f = std::log(J) + ratio_ * J, df = 1 / J + ratio_;
      J -= f / df;
      if (std::fabs(f) < 1e-15) break;
    }
    return J;
  }
  double volume(const Simulation<D>& sim) const {
    const auto& P = sim.particles;
    double v = 0;
    for (size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == body_) v += P.col(P.volume)[i];
    return v;
  }

  Params params_;
  double ratio_;
  bool hencky_;
  int body_ = 0, pore_ = -1;
  double H0_ = 1, V0_ = 1;
};

LOAM_REGISTER(Reference, ConsolidatedHeight)

}  // namespace loam
