// Reference: Terzaghi one-dimensional consolidation with one-way drainage (docs/verification.md C;
// series in plugins/references/terzaghi.hpp). The column is a body whose top face (the last axis,
// upward) is drained and whose base is impermeable; its excess pore pressure starts at p0 = `load`.
//
// It reads the particle field `pore_pressure` (compression positive, Pa), which a two-phase
// scheme requests. When the run time first reaches t_k = T_k H0^2 / c_v for each requested time
// factor T_k (H0 the body's initial height), it samples, at the actual time factor of that step
// T = c_v t / H0^2 (so the step that overshoots t_k is compared with the right exact values):
//   - max over the body's particles of |p/p0 - exact(zeta, T)|, zeta = z'/H at the particles'
//     CURRENT positions, z' measured down from the body's current top and H its current height.
//     The top and base faces lie half a particle spacing beyond the outermost particle centres;
//     that offset is scaled with the stretch of the particle span, so small strain reduces to
//     the initial geometry and large strain keeps zeta in [0, 1].
//   - the degree-of-consolidation error |U - U(T)|, U = 1 - <p>/p0 with <p> the volume-weighted
//     mean pore pressure of the body.
// Metrics: max_error_T<T> and consolidation_degree_error_T<T> for each T, max_error and
// consolidation_degree_error (worst over T; NaN if some T was never reached), drainage_length.
// Gravity: the exact solution is for the EXCESS pore pressure; a run with hydrostatic pore
// pressure needs a scheme that stores the excess or a reference option (not yet provided).
#include "plugins/references/terzaghi.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Terzaghi : public Reference<D> {
 public:
  static constexpr const char* name = "terzaghi";
  static constexpr const char* summary =
      "1D consolidation, drained top, impermeable base: pore pressure and degree of "
      "consolidation (needs a two-phase scheme)";
  static Schema schema() {
    Schema s;
    s.real("load", "Pa",
           "initial excess pore pressure p0 (the step load on the top, for incompressible "
           "constituents)")
        .required()
        .positive();
    s.real("consolidation_coefficient", "m^2/s",
           "c_v = k M / gamma_w (k hydraulic conductivity, M constrained modulus)")
        .required()
        .positive();
    s.real_list("time_factors", "-", "time factors T = c_v t / H^2 at which the column is sampled")
        .def("[0.05, 0.1, 0.2, 0.5, 1]")
        .positive();
    s.text("body", "the column (default: the first body)");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.vec("time_factors").empty())
        d.error(p.where("time_factors"), p.path("time_factors"), "give at least one time factor");
    });
    return s;
  }
  explicit Terzaghi(const Params& p)
      : params_(p),
        p0_(p.real("load")),
        cv_(p.real("consolidation_coefficient")),
        factors_(p.vec("time_factors")) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    pore_ = sim.sets[0].particles.find("pore_pressure");  // one layout in every set
    if (pore_ < 0)
      diag.error(params_.where(), params_.path(),
                 "terzaghi needs a two-phase scheme (no pore_pressure field)");
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    H0_ = b.upper[D - 1] - b.lower[D - 1];
    auto [zmin, zmax] = span(sim);
    span0_ = zmax - zmin;
    off_top_ = b.upper[D - 1] - zmax;
    off_base_ = zmin - b.lower[D - 1];
    max_err_.assign(factors_.size(), std::numeric_limits<double>::quiet_NaN());
    u_err_ = max_err_;
  }

  void sample(Simulation<D>& sim) override {
    const double T = cv_ * sim.time / (H0_ * H0_);
    bool due = false;
    for (size_t k = 0; k < factors_.size(); ++k)
      due = due || (std::isnan(max_err_[k]) && T >= factors_[k] * (1 - 1e-12));
    if (!due) return;
    // Current geometry: faces beyond the outermost particle centres, offsets stretched with them.
    auto [zmin, zmax] = span(sim);
    const double stretch = span0_ > 0 ? (zmax - zmin) / span0_ : 1.0;
    const double top = zmax + off_top_ * stretch, base = zmin - off_base_ * stretch;
    const double H = top - base;
    const auto& P = sim.particles_of_body(body_);
    const double* z = P.col(P.position, D - 1);
    const double* p = P.col(pore_);
    const double* V = P.col(P.volume);
    double err = 0, pv = 0, vol = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_) continue;
      const double zeta = std::clamp((top - z[i]) / H, 0.0, 1.0);
      err = std::max(err, std::fabs(p[i] / p0_ - terzaghi_pressure(zeta, T)));
      pv += V[i] * p[i];
      vol += V[i];
    }
    err = sim.ranks->max(err);  // over the ranks (identity serially)
    sum_over_ranks(*sim.ranks, pv, vol);
    const double u_err = std::fabs(1 - pv / (vol * p0_) - terzaghi_degree(T));
    for (size_t k = 0; k < factors_.size(); ++k)
      if (std::isnan(max_err_[k]) && T >= factors_[k] * (1 - 1e-12)) {
        max_err_[k] = err;
        u_err_[k] = u_err;
      }
  }

  std::map<std::string, double> metrics(Simulation<D>&) override {
    std::map<std::string, double> m;
    double worst = 0, worst_u = 0;
    for (size_t k = 0; k < factors_.size(); ++k) {
      const std::string T = format_number(factors_[k]);
      m["max_error_T" + T] = max_err_[k];
      m["consolidation_degree_error_T" + T] = u_err_[k];
      worst = std::isnan(max_err_[k]) ? max_err_[k] : std::max(worst, max_err_[k]);
      worst_u = std::isnan(u_err_[k]) ? u_err_[k] : std::max(worst_u, u_err_[k]);
    }
    m["max_error"] = worst;
    m["consolidation_degree_error"] = worst_u;
    m["drainage_length"] = H0_;
    return m;
  }

  /// The column's span and the largest error are maxima over the ranks, the mean pressure's
  /// integrals sums.
  bool runs_on_ranks() const override { return true; }

  bool save_state(std::vector<double>& s) const override {
    s = max_err_;  // the geometry (H0, span0, offsets) is the set-up's, recomputed on resume
    s.insert(s.end(), u_err_.begin(), u_err_.end());
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    const size_t n = max_err_.size();
    max_err_.assign(s.begin(), s.begin() + long(n));
    u_err_.assign(s.begin() + long(n), s.begin() + long(2 * n));
  }

 private:
  std::pair<double, double> span(const Simulation<D>& sim) const {
    const auto& P = sim.particles_of_body(body_);
    const double* z = P.col(P.position, D - 1);
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == body_) lo = std::min(lo, z[i]), hi = std::max(hi, z[i]);
    return {-sim.ranks->max(-lo), sim.ranks->max(hi)};  // over the ranks
  }

  Params params_;
  double p0_, cv_;
  std::vector<double> factors_;
  int pore_ = -1, body_ = 0;
  double H0_ = 1, span0_ = 0, off_top_ = 0, off_base_ = 0;
  std::vector<double> max_err_, u_err_;  // per time factor; NaN until sampled
};

LOAM_REGISTER(Reference, Terzaghi)

}  // namespace loam
