// Reference: first mode of a bar fixed at x = 0 and free at x = L (VERIFICATION.md A).
// v(x,t) = v0 sin(pi x / 2L) cos(w t), u = (v0/w) sin(pi x / 2L) sin(w t), w = (pi/2L) sqrt(E/rho).
// Metrics: period from the tip velocity's zero crossings, tip amplitude, total-energy drift.
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class VibratingBar : public Reference<D> {
 public:
  static constexpr const char* name = "vibrating_bar";
  static constexpr const char* summary = "axial vibration of a bar, fixed at x=0, free at x=L";
  static Schema schema() {
    Schema s;
    s.text("body", "the bar (default: the first body)");
    s.real("v0", "m/s", "initial velocity amplitude of the mode").def("0.1").positive();
    return s;
  }
  explicit VibratingBar(const Params& p) : params_(p), v0_(p.real("v0")) {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    body_ = params_.has("body") ? sim.body_index(params_.text("body")) : 0;
    if (body_ < 0) {
      diag.error(params_.where("body"), params_.path("body"),
                 "unknown body '" + params_.text("body") + "'");
      return;
    }
    const Body& b = sim.bodies[size_t(body_)];
    const Params& mat = b.params.section("material");
    if (!mat.has("E")) {
      diag.error(params_.where(), params_.path(), "vibrating_bar needs an elastic body with 'E'");
      return;
    }
    length_ = b.upper[0] - b.lower[0];
    omega_ = M_PI / (2 * length_) * std::sqrt(mat.real("E") / mat.real("density"));
    // The tip: the particle of the body farthest along x.
    double best = -1e300;
    const auto& P = sim.particles;
    for (size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == body_ && P.col(P.position, 0)[i] > best)
        best = P.col(P.position, 0)[i], tip_ = P.id[i];
    x_tip0_ = best;
    e0_ = energy(sim);
  }

  void sample(Simulation<D>& sim) override {
    const auto& P = sim.particles;
    size_t i = sim.index_of(tip_);
    const double v = P.col(P.velocity, 0)[i];
    const double u = P.col(P.position, 0)[i] - x_tip0_;
    max_u_ = std::max(max_u_, std::fabs(u));
    // Downward zero crossings of the tip velocity, linearly interpolated in time.
    if (last_v_ > 0 && v <= 0) {
      double t = last_t_ + (sim.time - last_t_) * last_v_ / (last_v_ - v);
      crossings_.push_back(t);
    }
    last_v_ = v;
    last_t_ = sim.time;
    drift_ = std::max(drift_, std::fabs(energy(sim) - e0_) / e0_);
  }

  std::map<std::string, double> metrics(Simulation<D>&) override {
    const double period = 2 * M_PI / omega_;
    std::map<std::string, double> m;
    m["period_exact"] = period;
    m["amplitude_exact"] = v0_ / omega_ * std::sin(M_PI * x_tip0_ / (2 * length_));
    m["amplitude_measured"] = max_u_;
    m["amplitude_error"] = std::fabs(max_u_ / m["amplitude_exact"] - 1);
    m["energy_drift"] = drift_;
    m["periods_observed"] = crossings_.size() > 1 ? double(crossings_.size() - 1) : 0.0;
    if (crossings_.size() > 1) {
      double measured = (crossings_.back() - crossings_.front()) / double(crossings_.size() - 1);
      m["period_measured"] = measured;
      m["period_error"] = std::fabs(measured / period - 1);
    } else {
      m["period_error"] = 1.0;  // not a single period seen: fail loudly
    }
    return m;
  }

 private:
  double energy(Simulation<D>& sim) {
    Energies e = sim.energies();
    return e.kinetic + e.strain;
  }
  Params params_;
  double v0_, length_ = 0, omega_ = 0, x_tip0_ = 0, e0_ = 0;
  int body_ = 0;
  uint32_t tip_ = 0;
  double last_v_ = 0, last_t_ = 0, max_u_ = 0, drift_ = 0;
  std::vector<double> crossings_;
};

LOAM_REGISTER(Reference, VibratingBar)

}  // namespace loam
