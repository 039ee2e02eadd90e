// Reference: final height of a laterally confined elastic column consolidated under a surface
// load q (the large-strain column of the FEM-and-MPM comparison of large-strain consolidation,
// seed 001; docs/verification.md C "Seed 001, large strain"). Once the excess pore pressure has
// drained, the effective stress is -q everywhere (no self-weight), and the exact height h = J H0
// follows from the stress-strain law along the column axis (nu = 0, M the constrained modulus):
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
#include "plugins/references/column.hpp"

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

  void setup(Simulation<D>& sim, Diagnostics& diag) override { col_.setup(sim, params_, diag); }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    std::map<std::string, double> m;
    const double h = col_.height(sim), exact = col_.H0 * stretch();
    m["final_height"] = h;
    m["exact_height"] = exact;
    m["height_error"] = (h - exact) / exact;
    if (col_.pore >= 0)
      m["residual_pore_pressure"] = col_.max_pore_pressure(sim) / params_.real("load");
    if (params_.has("paper_height")) {
      m["paper_height"] = params_.real("paper_height");
      m["height_vs_paper"] = (h - m["paper_height"]) / m["paper_height"];
    }
    return m;
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"final_height", "exact_height", "exact"},
            {"final_height", "paper_height", "the paper"}};
  }

  /// The column's sums and largest pore pressure are over the ranks (column.hpp).
  bool runs_on_ranks() const override { return true; }
  /// Checkpoints: nothing accumulates; everything is the set-up's or the final state's.
  bool save_state(std::vector<double>&) const override { return true; }

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
  Params params_;
  double ratio_;
  bool hencky_;
  Column<D> col_;
};

LOAM_REGISTER(Reference, ConsolidatedHeight)

}  // namespace loam
