// Reference: first mode of a bar fixed at x = 0 and free at x = L (docs/verification.md A).
// v(x,t) = v0 sin(pi x / 2L) cos(w t), u = (v0/w) sin(pi x / 2L) sin(w t), w = (pi/2L) sqrt(E/rho).
// Metrics: period from the zero crossings and amplitude of the first-mode coordinate
//   q(t) = sum m u phi / sum m phi^2,  phi = sin(pi x0 / 2L)
// (a projection that filters the other modes, which are orthogonal to phi, so the noise of
// higher modes cannot add spurious crossings), the total-energy drift, and the displacement
// error: max over time of the mass-weighted RMS of u - u_exact over the bar, over v0/w.
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
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    const Params& mat = b.params.section("material");
    if (!mat.has("E")) {
      diag.error(params_.where(), params_.path(), "vibrating_bar needs an elastic body with 'E'");
      return;
    }
    length_ = b.upper[0] - b.lower[0];
    x0_ = b.lower[0];
    omega_ = M_PI / (2 * length_) * std::sqrt(mat.real("E") / mat.real("density"));
    // Mode shape at the initial positions, kept by particle id (ids count over all sets). Under
    // mpirun every rank keeps the whole bar's: a particle may move to another rank.
    const auto& P = sim.particles_of_body(body_);
    std::vector<double> own;  // id, x, mass of this rank's particles of the bar
    for (size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == body_)
        own.insert(own.end(), {double(P.id[i]), P.col(P.position, 0)[i], P.col(P.mass)[i]});
    const std::vector<double> all = sim.ranks->all_gather(own);
    phi_.assign(sim.next_particle_id(), 0.0);
    x_init_.assign(phi_.size(), 0.0);
    norm_ = 0;
    for (size_t k = 0; k + 2 < all.size(); k += 3) {
      const size_t id = size_t(all[k]);
      const double x = all[k + 1];
      phi_[id] = std::sin(M_PI * (x - x0_) / (2 * length_));
      x_init_[id] = x;
      norm_ += all[k + 2] * phi_[id] * phi_[id];
    }
    e0_ = energy(sim);
  }

  void sample(Simulation<D>& sim) override {
    const auto& P = sim.particles_of_body(body_);
    const double* m = P.col(P.mass);
    const double* x = P.col(P.position, 0);
    const double* vel = P.col(P.velocity, 0);
    double qd = 0, q = 0, err2 = 0, mass = 0;
    const double u_amp = v0_ / omega_, s = std::sin(omega_ * sim.time);
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_) continue;
      const double ph = phi_[P.id[i]];
      const double u = x[i] - x_init_[P.id[i]];
      qd += m[i] * vel[i] * ph;
      q += m[i] * u * ph;
      err2 += m[i] * std::pow(u - u_amp * ph * s, 2);  // u_exact = (v0/w) phi sin(w t)
      mass += m[i];
    }
    sum_over_ranks(*sim.ranks, qd, q, err2, mass);  // identity serially
    // Mass-weighted RMS displacement error relative to the tip amplitude, worst over time.
    field_error_ = std::max(field_error_, std::sqrt(err2 / mass) / u_amp);
    qd /= norm_;
    q /= norm_;
    max_u_ = std::max(max_u_, std::fabs(q));
    // Downward zero crossings of the modal velocity, linearly interpolated in time.
    if (last_v_ > 0 && qd <= 0)
      crossings_.push_back(last_t_ + (sim.time - last_t_) * last_v_ / (last_v_ - qd));
    last_v_ = qd;
    last_t_ = sim.time;
    drift_ = std::max(drift_, std::fabs(energy(sim) - e0_) / e0_);
  }

  std::map<std::string, double> metrics(Simulation<D>&) override {
    const double period = 2 * M_PI / omega_;
    std::map<std::string, double> m;
    m["period_exact"] = period;
    m["amplitude_exact"] = v0_ / omega_;  // of the modal displacement q
    m["amplitude_measured"] = max_u_;
    m["amplitude_error"] = std::fabs(max_u_ / m["amplitude_exact"] - 1);
    m["energy_drift"] = drift_;
    m["displacement_error"] = field_error_;
    m["periods_observed"] = crossings_.size() > 1 ? double(crossings_.size() - 1) : 0.0;
    if (crossings_.size() > 1) {
      double measured = (crossings_.back() - crossings_.front()) / double(crossings_.size() - 1);
      m["period_measured"] = measured;
      m["period_error"] = std::fabs(measured / period - 1);
    }  // fewer than two crossings: no period metrics (a test reading them then fails loudly)
    return m;
  }

  std::vector<Comparison> comparisons(const std::map<std::string, double>&) const override {
    return {{"period_measured", "period_exact", "first mode"},
            {"amplitude_measured", "amplitude_exact", "first mode"}};
  }

  /// Every rank keeps the whole bar's mode shape; the modal sums are over the ranks.
  bool runs_on_ranks() const override { return true; }

  bool save_state(std::vector<double>& s) const override {
    s = {last_v_, last_t_, max_u_, drift_, field_error_};
    s.insert(s.end(), crossings_.begin(), crossings_.end());
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    last_v_ = s.at(0), last_t_ = s.at(1), max_u_ = s.at(2), drift_ = s.at(3);
    field_error_ = s.at(4);
    crossings_.assign(s.begin() + 5, s.end());
  }

 private:
  double energy(Simulation<D>& sim) {
    Energies e = sim.energies();
    return e.kinetic + e.strain;
  }
  Params params_;
  double v0_, length_ = 0, omega_ = 0, x0_ = 0, e0_ = 0, norm_ = 0;
  int body_ = 0;
  std::vector<double> phi_, x_init_;  // by particle id
  double last_v_ = 0, last_t_ = 0, max_u_ = 0, drift_ = 0, field_error_ = 0;
  std::vector<double> crossings_;
};

LOAM_REGISTER(Reference, VibratingBar)

}  // namespace loam
