// Reference: collapse of a granular column released against a wall onto a horizontal base.
// Measures the deposit: run-out of the front and final height, normalised by the initial column
// width L0 and height H0 (aspect ratio a = H0/L0), beside the empirical scaling of quasi-2D
// laboratory collapses (Lube, Huppert, Sparks & Freundt 2005, Phys. Rev. E 72, 041301):
//   (L_f - L0)/L0 = 1.2 a            for a < 1.8,      1.9 a^(2/3)   for a > 2.8,
//   H_f/L0        = a                for a < 1.15,     a^(2/5)       otherwise.
// Between the two run-out regimes the empirical value is interpolated linearly in a and reported
// as such. These are experimental trends, not exact solutions: a continuum Mohr-Coulomb model is
// expected within roughly 20-30 % of them. x is the spreading direction (the column stands at
// its low-x side), the last axis is vertical; lengths use particle domains (positions +- half the
// initial particle spacing) so that the initial values equal the body's geometry.
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class GranularCollapse : public Reference<D> {
 public:
  static constexpr const char* name = "granular_collapse";
  static constexpr const char* summary =
      "granular column collapse: run-out and final height vs Lube et al. (2005) scaling";
  static Schema schema() {
    Schema s;
    s.text("body", "the column (default: the first body)");
    return s;
  }
  explicit GranularCollapse(const Params& p) : params_(p) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (D < 2) {
      diag.error(params_.where(), params_.path(), "granular_collapse needs a 2D or 3D grid");
      return;
    }
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    x0_ = b.lower[0];
    L0_ = b.upper[0] - b.lower[0];
    base_ = b.lower[D - 1];
    H0_ = b.upper[D - 1] - base_;
    half_x_ = 0.5 * b.spacing[0];
    half_z_ = 0.5 * b.spacing[D - 1];
  }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    const auto& P = sim.particles_of_body(body_);
    double front = -1e300, top = -1e300, v2 = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_) continue;
      front = std::max(front, P.col(P.position, 0)[i] + half_x_);
      top = std::max(top, P.col(P.position, D - 1)[i] + half_z_);
      double s = 0;
      for (int d = 0; d < D; ++d) s += std::pow(P.col(P.velocity, d)[i], 2);
      v2 = std::max(v2, s);
    }
    front = sim.ranks->max(front);  // over the ranks (identity serially)
    top = sim.ranks->max(top);
    v2 = sim.ranks->max(v2);
    const double a = H0_ / L0_;
    std::map<std::string, double> m;
    m["aspect_ratio"] = a;
    m["runout"] = front - (x0_ + L0_);
    m["final_height"] = top - base_;
    m["runout_ratio"] = m["runout"] / L0_;        // (L_f - L0)/L0
    m["height_ratio"] = m["final_height"] / L0_;  // H_f/L0
    m["lube2005_runout_ratio"] = lube_runout(a);
    m["lube2005_height_ratio"] = a < 1.15 ? a : std::pow(a, 0.4);
    // |(L_f - L0)/L0 / Lube's - 1|: the error `loam compare` plots against wall time.
    m["runout_error"] = std::fabs(m["runout_ratio"] / m["lube2005_runout_ratio"] - 1);
    m["max_speed_final"] = std::sqrt(v2);
    return m;
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"runout_ratio", "lube2005_runout_ratio", "Lube et al. 2005"},
            {"height_ratio", "lube2005_height_ratio", "Lube et al. 2005"}};
  }

  /// Checkpoints: nothing accumulates; everything is the set-up's or the final state's.
  bool save_state(std::vector<double>&) const override { return true; }
  /// The front, the top and the largest speed are maxima over the ranks.
  bool runs_on_ranks() const override { return true; }

 private:
  static double lube_runout(double a) {
    if (a < 1.8) return 1.2 * a;
    if (a > 2.8) return 1.9 * std::pow(a, 2.0 / 3.0);
    const double lo = 1.2 * 1.8, hi = 1.9 * std::pow(2.8, 2.0 / 3.0);
    return lo + (hi - lo) * (a - 1.8) / (2.8 - 1.8);
  }

  Params params_;
  int body_ = 0;
  double x0_ = 0, L0_ = 1, base_ = 0, H0_ = 1, half_x_ = 0, half_z_ = 0;
};

LOAM_REGISTER(Reference, GranularCollapse)

}  // namespace loam
