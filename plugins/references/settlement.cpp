// Reference: final settlement of a laterally confined column under a surface load, for any
// skeleton material (the MCC column after the FEM-and-MPM comparison of large-strain
// consolidation, seed 001; docs/verification.md C "Seed 001, MCC"). It measures; the value
// to compare with comes from elsewhere (for an elastoplastic skeleton: the oedometric element test
// of the same material from the same initial state to the same final vertical effective stress,
// `loam element-test`, given here as expected_settlement).
//   final_height     = sum V_p / A0, A0 = V0 / H0 (m): the column's current volume over its
//                      initial cross-section (counts the half particle beyond the outermost
//                      centres at both faces, as consolidated_height does)
//   final_settlement = H0 - final_height (m), H0 the initial height of the body along the last
//                      axis (the vertical of a 1D, 2D or 3D column)
// For a uniform column h / H0 = V / V0 = (1 + e) / (1 + e0), so final_settlement / H0 equals
// the element test's 1 - exp(-eps_a) (eps_a its logarithmic axial strain).
// Metrics (at the end of the run): final_height, final_settlement (m), vertical_stress (Pa, the
// volume-weighted mean effective stress along the last axis over the body, COMPRESSION POSITIVE;
// the applied load plus any initial stress once drained), residual_pore_pressure (max |p| / load
// over the body, p the excess pore pressure; near 0 once consolidation is complete; only with a
// two-phase scheme), and when given: settlement_error = (final_settlement - expected) / expected,
// paper_settlement and settlement_vs_paper (relative).
#include <cmath>

#include "framework/registry.hpp"
#include "plugins/references/column.hpp"

namespace loam {

template <int D>
class Settlement : public Reference<D> {
 public:
  static constexpr const char* name = "settlement";
  static constexpr const char* summary =
      "final settlement H0 - sum V / A0 of a confined column under a surface load, against an "
      "expected value (e.g. an oedometric element test) and residual pore pressure";
  static Schema schema() {
    Schema s;
    s.real("load", "Pa",
           "surface load added at the start (compression positive); scales residual_pore_pressure")
        .required()
        .positive();
    s.real("expected_settlement", "m",
           "settlement to compare with, e.g. H0 (1 - exp(-eps_a)) from the oedometric element "
           "test of the same material (optional; gives settlement_error)")
        .positive();
    s.real("paper_settlement", "m", "a published final settlement to report beside (optional)")
        .positive();
    s.text("body", "the column (default: the first body)");
    return s;
  }
  explicit Settlement(const Params& p) : params_(p) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override { col_.setup(sim, params_, diag); }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    const auto& P = sim.particles_of_body(col_.body);
    const double* V = P.col(P.volume);
    const double* sv = P.col(P.stress, D - 1);  // normal stress along the last axis
    std::map<std::string, double> m;
    const double vol = col_.sum(sim, [&](size_t i) { return V[i]; });
    const double h = col_.height(sim), s = col_.H0 - h;
    m["final_height"] = h;
    m["final_settlement"] = s;
    m["vertical_stress"] = -col_.sum(sim, [&](size_t i) { return V[i] * sv[i]; }) / vol;
    if (col_.pore >= 0)
      m["residual_pore_pressure"] = col_.max_pore_pressure(sim) / params_.real("load");
    if (params_.has("expected_settlement")) {
      m["expected_settlement"] = params_.real("expected_settlement");
      m["settlement_error"] = (s - m["expected_settlement"]) / m["expected_settlement"];
    }
    if (params_.has("paper_settlement")) {
      m["paper_settlement"] = params_.real("paper_settlement");
      m["settlement_vs_paper"] = (s - m["paper_settlement"]) / m["paper_settlement"];
    }
    return m;
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"final_settlement", "expected_settlement", "expected_settlement"},
            {"final_settlement", "paper_settlement", "the paper"}};
  }

  /// The column's sums and largest pore pressure are over the ranks (column.hpp).
  bool runs_on_ranks() const override { return true; }
  /// Checkpoints: nothing accumulates; everything is the set-up's or the final state's.
  bool save_state(std::vector<double>&) const override { return true; }

 private:
  Params params_;
  Column<D> col_;
};

LOAM_REGISTER(Reference, Settlement)

}  // namespace loam
