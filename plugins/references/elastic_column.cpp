// Reference: laterally confined elastic column under gravity on a fixed base
// (docs/verification.md A): sigma_v(z) = -rho g (H - z), sigma_h = nu/(1-nu) sigma_v,
// u_v(z) = -rho g (H z - z^2/2) / M with M = E(1-nu)/((1+nu)(1-2nu)); the top settles
// rho g H^2 / (2M). Vertical is the last axis; z is measured from the column's base, and the
// exact fields are evaluated at each particle's initial position (small strain).
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class ElasticColumn : public Reference<D> {
 public:
  static constexpr const char* name = "elastic_column";
  static constexpr const char* summary =
      "confined elastic column under self-weight: stress and settlement";
  static Schema schema() {
    Schema s;
    s.text("body", "the column (default: the first body)");
    return s;
  }
  explicit ElasticColumn(const Params& p) : params_(p) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    const Params& mat = b.params.section("material");
    if (!mat.has("E") || !mat.has("nu")) {
      diag.error(params_.where(), params_.path(),
                 "elastic_column needs an elastic body with 'E' and 'nu'");
      return;
    }
    E_ = mat.real("E");
    nu_ = mat.real("nu");
    rho_ = mat.real("density");
    g_ = -sim.gravity[D - 1];
    base_ = b.lower[D - 1];
    H_ = b.upper[D - 1] - base_;
    M_ = E_ * (1 - nu_) / ((1 + nu_) * (1 - 2 * nu_));
    z0_ = sim.request_displacement_reference();
  }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    const auto& P = sim.particles_of_body(body_);
    const int v_comp = D - 1;           // Voigt index of sigma along the last axis
    const int h_comp = D == 1 ? 1 : 0;  // a lateral normal stress
    double mean_sv = 0, vol = 0, e2 = 0, r2 = 0, h2 = 0, hr2 = 0, u2 = 0, ur2 = 0, top_u = 0,
           top_z = -1e300;
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_) continue;
      const double V = P.col(P.volume)[i];
      const double z = P.col(z0_, D - 1)[i] - base_;
      const double sv = -rho_ * g_ * (H_ - z);
      const double sh = nu_ / (1 - nu_) * sv;
      const double uz = -rho_ * g_ * (H_ * z - 0.5 * z * z) / M_;
      const double u = P.col(P.position, D - 1)[i] - P.col(z0_, D - 1)[i];
      mean_sv += V * P.col(P.stress, v_comp)[i];
      vol += V;
      e2 += V * std::pow(P.col(P.stress, v_comp)[i] - sv, 2);
      r2 += V * sv * sv;
      h2 += V * std::pow(P.col(P.stress, h_comp)[i] - sh, 2);
      hr2 += V * sh * sh;
      u2 += V * (u - uz) * (u - uz);
      ur2 += V * uz * uz;
      if (z > top_z) top_z = z, top_u = u;
    }
    // Over the ranks: the sums, and the top particle of the rank holding the highest one (of
    // equally high ones the first rank's, as serially the first particle's).
    sum_over_ranks(*sim.ranks, mean_sv, vol, e2, r2, h2, hr2, u2, ur2);
    const std::vector<double> tops = sim.ranks->all_gather({top_z, top_u});
    for (size_t k = 0; k + 1 < tops.size(); k += 2)
      if (k == 0 || tops[k] > top_z) top_z = tops[k], top_u = tops[k + 1];
    std::map<std::string, double> m;
    m["stress_error_l2"] = std::sqrt(e2 / r2);
    m["horizontal_stress_error_l2"] = hr2 > 0 ? std::sqrt(h2 / hr2) : std::sqrt(h2 / r2);
    m["displacement_error_l2"] = std::sqrt(u2 / ur2);
    m["mean_vertical_stress"] = mean_sv / vol;  // for comparing 1D, 2D and 3D runs
    m["settlement_exact"] = rho_ * g_ * H_ * H_ / (2 * M_);
    m["settlement_top_particle"] = -top_u;
    return m;
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"settlement_top_particle", "settlement_exact", "rho g H^2 / (2 M)"}};
  }

  /// The column's integrals are sums over the ranks, its top particle the highest over them.
  bool runs_on_ranks() const override { return true; }
  /// Checkpoints: nothing accumulates; everything is the set-up's or the final state's.
  bool save_state(std::vector<double>&) const override { return true; }

 private:
  Params params_;
  int body_ = 0, z0_ = -1;
  double E_ = 0, nu_ = 0, rho_ = 0, g_ = 0, base_ = 0, H_ = 0, M_ = 0;
};

LOAM_REGISTER(Reference, ElasticColumn)

}  // namespace loam
