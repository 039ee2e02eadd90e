// Example out-of-tree plugin: a Kelvin-Voigt viscoelastic solid (a spring and a dashpot in
// parallel), built as its own shared library and loaded by a run file with
//   plugins: [path/to/libexample_kelvin_voigt.so]
// Copy this directory to start a plugin of your own; README.md says how to build and load it.
//
// The Cauchy stress (tension positive) is the sum of
//   an elastic part, hypoelastic with the Jaumann rate exactly as the built-in linear_elastic:
//     sigma_e^{n+1} = sigma_e^n + (w sigma_e - sigma_e w) + lambda tr(d) I + 2 G d,
//   and a viscous part proportional to the current strain rate:
//     sigma_v = eta sym(L)            (1D: sigma = M eps + eta d(eps)/dt),
// with d = sym(L) dt, w = skew(L) dt. The particle `stress` field holds the total; the viscous part
// of the last step is kept in a per-particle field `viscous_stress` that this material requests in
// setup() (allocated only when some body uses it), so that the elastic part can be recovered,
// rotated and updated. An initial stress given in the run file counts as elastic.
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"

// Your own namespace: an out-of-tree class can never clash with a built-in of the same name.
namespace loam_example {

using loam::MaterialBatch;
using loam::Params;
using loam::Particles;
using loam::Schema;

template <int D>
class KelvinVoigt : public loam::Material<D> {
 public:
  static constexpr const char* name = "example_kelvin_voigt";
  static constexpr const char* summary =
      "Kelvin-Voigt viscoelastic solid: linear elastic + eta * strain rate (example plugin)";
  static Schema schema() {
    Schema s;
    s.real("E", "Pa", "Young's modulus of the spring").required().positive();
    s.real("nu", "-", "Poisson's ratio of the spring").required().above(-1).below(0.5);
    s.real("density", "kg/m^3", "mass density").required().positive();
    s.real("viscosity", "Pa*s", "dashpot viscosity eta: viscous stress = eta * sym(L)")
        .required()
        .non_negative();
    return s;
  }
  explicit KelvinVoigt(const Params& p)
      : E_(p.real("E")), nu_(p.real("nu")), rho_(p.real("density")), eta_(p.real("viscosity")) {
    G_ = E_ / (2 * (1 + nu_));
    lambda_ = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_));
    M_ = lambda_ + 2 * G_;  // constrained (P-wave) modulus
  }

  double density() const override { return rho_; }

  void setup(loam::Simulation<D>& sim, int index, loam::Diagnostics&) override {
    // State fields are requested through the Simulation, in the set of the body.
    viscous_ = sim.request_field(
        {"viscous_stress", Particles<D>::NS, "Pa",
         "viscous part of the stress (Kelvin-Voigt dashpot)", Particles<D>::stress_names()},
        sim.body_set(index));
    h_ = sim.grid.min_cell();
    threads_ = sim.threads;  // the run's --threads: OpenMP's default would ignore it
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    // The dashpot lowers the explicit stability limit. For the highest grid mode (frequency
    // w = 2c/h) the damping ratio is z = eta c / (M h), and central differences are stable for
    // dt <= (h/c)(sqrt(1 + z^2) - z). Returning c (sqrt(1 + z^2) + z) makes the framework's
    // dt = cfl h / c_eff respect that: elastic CFL for eta = 0, cfl rho h^2 / (2 eta) when the
    // dashpot dominates. c_eff decreases with density, so the least dense particle sets it.
    double rho_min = std::numeric_limits<double>::infinity();
    const double* m = P.col(P.mass);
    const double* V = P.col(P.volume);
#pragma omp parallel for num_threads(threads_) reduction(min : rho_min) schedule(static)
    for (size_t i = b; i < e; ++i) rho_min = std::min(rho_min, m[i] / V[i]);
    const double rho = std::max(rho_min, 1e-300);
    const double c = std::sqrt(M_ / rho);
    const double z = eta_ / (h_ * std::sqrt(M_ * rho));
    return c * (std::sqrt(1 + z * z) + z);
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    // Voigt component c is the tensor component (I[c], J[c]).
    constexpr int I[6] = {0, 1, 2, 0, 1, 0}, J[6] = {0, 1, 2, 1, 2, 2};
    Particles<D>& P = *batch.particles;
    double* s[NS];
    double* v[NS];
    for (int c = 0; c < NS; ++c) {
      s[c] = P.col(P.stress, c) + batch.begin;
      v[c] = P.col(viscous_, c) + batch.begin;
    }
    for (int p = 0; p < batch.count; ++p) {
      const size_t q = size_t(p);
      for (int c = 0; c < NS; ++c) s[c][q] -= v[c][q];  // the elastic part
      loam::jaumann_elastic_update<D>(s, batch.L, loam::kBlock, q, batch.dt, lambda_, 2 * G_);
      double rate[3][3], spin[3][3];  // sym(L) and skew(L): dt = 1 gives rates, not increments
      loam::strain_and_spin<D>(batch.L, loam::kBlock, q, 1.0, rate, spin);
      for (int c = 0; c < NS; ++c) {
        v[c][q] = eta_ * rate[I[c]][J[c]];
        s[c][q] += v[c][q];
      }
    }
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    // Energy stored in the spring only: W = 1/2 sigma_e : C^-1 : sigma_e V, sigma_e = sigma -
    // sigma_v (the dashpot stores nothing; it dissipates).
    constexpr int NS = Particles<D>::NS;
    const double* V = P.col(P.volume);
    double sum = 0;
    for (size_t i = b; i < e; ++i) {
      double sv[6] = {0, 0, 0, 0, 0, 0};
      for (int c = 0; c < NS; ++c) sv[c] = P.col(P.stress, c)[i] - P.col(viscous_, c)[i];
      sum += V[i] * loam::isotropic_energy_density(sv, E_, nu_);
    }
    return sum;
  }

 private:
  double E_, nu_, rho_, eta_, G_, lambda_, M_;
  double h_ = 1.0;    // smallest grid cell size (m), for the time-step limit
  int viscous_ = -1;  // handle of the viscous_stress particle field
  int threads_ = 1;
};

LOAM_REGISTER(Material, KelvinVoigt)

}  // namespace loam_example

// The one symbol loam looks up after dlopen: it refuses a library built against another plugin
// interface. Keep it exactly like this in your own plugin library (once per library).
extern "C" __attribute__((visibility("default"))) int loam_plugin_abi_version() {
  return loam::kPluginAbiVersion;
}
