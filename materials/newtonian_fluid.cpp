// Weakly compressible Newtonian fluid (water) for free-surface flows, and the fluid phase of
// later two-phase schemes.
//
// Sign convention: Cauchy stress, TENSION POSITIVE, Voigt xx yy zz xy yz xz (1D: xx yy zz, no
// lateral strain rate; 2D: plane strain, xx yy zz xy; 3D: all six). Pressure p compression
// positive (gauge: p = 0 at the reference density).
//
//   rho   = m / V        current density of the particle (the framework updates the volume,
//                        V^{n+1} = det(I + L dt) V^n, before calling the material)
//   p     = K (rho / rho0 - 1)                  linear equation of state (Tait with exponent 1)
//   p     = max(p, -cavitation_pressure)        if a cavitation pressure is given
//   sigma = -p I + 2 mu dev(D),  D = sym(L)     (the strain RATE; dev in 3D, so in 2D plane
//                                                strain sigma_zz = -p - 2 mu tr(D) / 3)
// Stokes' hypothesis: no bulk viscosity. The stress keeps no memory (no deviatoric stress is
// integrated), so a rigid rotation (D = 0) produces no stress and no objective rate is needed.
// The pressure is a function of the density alone, so an initial `stress:` of the body sets
// its density (initialize: rho = rho0 (1 + p/K) with p = -tr(sigma)/3, V = m / rho): a
// hydrostatic body starts in equilibrium instead of being compressed by gravity within a few
// sound-crossing times. A particle with no initial pressure keeps its volume untouched. Linear
// rather than logarithmic (p = K ln(rho/rho0)) equation of state: the usual weakly compressible
// choice, with a sound speed independent of the density (below); the two differ by O((rho/rho0 -
// 1)^2), under 1e-4 K at 1% compression. Note: under a pure spin the schemes' volume update det(I +
// L dt) = 1 + (w dt)^2 dilates a particle by O((w dt)^2) per step, which this model turns into a
// tension of about K (w dt)^2 per step (measured in the tests: 49 kPa after 90 degrees in 1000
// steps with K = 20 MPa).
//
// Suspension viscosity (suspension_viscosity: true, for the liquid points of the double-point
// scheme in cells shared with grains; docs/verification.md F): mu_eff = mu (1 + 2.5 c + 5.2 c^2)
// with c = 1 - n the solid concentration, n the particle's `porosity` field where it has one (the
// double-point scheme's liquid points: the porosity of the step), 1 elsewhere. 2.5 c is
// Einstein's dilute limit; the form with 5.2 c^2 is the one the sources of Liang, Zhao &
// Martinelli, "MPM simulations of the interaction between water jet and soil bed" (seed 003) give
// for Anura3D.
// Sound speed: c^2 = dp/drho = K / rho0 for this equation of state, the same for every density
// (a compressed particle is stiffer, tangent bulk modulus K rho / rho0, but also denser: the
// two cancel), and in the cavitated state dp/drho = 0. The CFL speed is therefore sqrt(K / rho0).
// Viscous limit: the explicit stress update of the viscous term is stable for
// dt <= rho h^2 / (2 D mu) (h the smallest cell size). wave_speed folds it in as the speed
// 2 D mu / (rho_min h), so that the framework's dt = cfl h / c respects it (for water,
// mu = 1e-3 Pa s, h = 1 cm, 3D: 6e-4 m/s against c = 1483 m/s, i.e. negligible).
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"
#include "plausible.hpp"

namespace loam {

template <int D>
class NewtonianFluid : public Material<D> {
 public:
  static constexpr const char* name = "newtonian_fluid";
  static constexpr const char* summary =
      "weakly compressible Newtonian fluid (water): p = K (rho/rho0 - 1), sigma = -p I + "
      "2 mu dev(D), optional cavitation cutoff";
  static Schema schema() {
    Schema s;
    s.real("bulk_modulus", "Pa", "bulk modulus K of the equation of state p = K (rho/rho0 - 1)")
        .required()
        .positive();
    s.real("viscosity", "Pa s", "dynamic viscosity mu (water: 1e-3; 0: inviscid)")
        .required()
        .non_negative();
    plausible_density(
        s.real("density", "kg/m^3", "reference density rho0 (p = 0)").required().positive());
    s.boolean("suspension_viscosity",
              "mu (1 + 2.5 c + 5.2 c^2) with c = 1 - porosity where the particle has a porosity "
              "field (water among grains in the double-point scheme)")
        .def("false");
    s.real("cavitation_pressure", "Pa",
           "largest tension the fluid carries: p >= -cavitation_pressure (0: no tension); "
           "default: no limit")
        .non_negative();
    return s;
  }

  explicit NewtonianFluid(const Params& p)
      : K_(p.real("bulk_modulus")),
        mu_(p.real("viscosity")),
        rho0_(p.real("density")),
        p_min_(p.has("cavitation_pressure") ? -p.real("cavitation_pressure")
                                            : -std::numeric_limits<double>::infinity()),
        suspension_(p.flag("suspension_viscosity")) {}

  double density() const override { return rho0_; }
  bool is_fluid() const override { return true; }

  void setup(Simulation<D>& sim, int, Diagnostics&) override { h_ = sim.grid.min_cell(); }

  /// The density that gives the initial pressure p = -tr(sigma)/3: V = m / (rho0 (1 + p/K)).
  /// A particle at p = 0 is left alone (its V is the generator's, m = rho0 V to round-off).
  void initialize(Particles<D>& P, size_t b, size_t e) override {
    const double* m = P.col(P.mass);
    double* V = P.col(P.volume);
    for (size_t i = b; i < e; ++i) {
      double p = 0;
      for (int c = 0; c < 3; ++c) p -= P.col(P.stress, c)[i] / 3;
      p = std::max(p, p_min_);  // no more tension than the fluid carries
      if (p != 0 && 1 + p / K_ > 0) V[i] = m[i] / (rho0_ * (1 + p / K_));
    }
  }

  /// Pressure (Pa, compression positive) at density rho.
  double pressure(double rho) const { return std::max(K_ * (rho / rho0_ - 1), p_min_); }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    const double c = std::sqrt(K_ / rho0_);
    if (mu_ == 0 || !(h_ > 0)) return c;
    double rho_min = std::numeric_limits<double>::infinity();
    const double* m = P.col(P.mass);
    const double* V = P.col(P.volume);
#pragma omp parallel for reduction(min : rho_min) schedule(static)
    for (size_t i = b; i < e; ++i) rho_min = std::min(rho_min, m[i] / V[i]);
    // The suspension factor is at most 1 + 2.5 + 5.2 = 8.7 (c = 1).
    const double mu = suspension_ ? 8.7 * mu_ : mu_;
    return std::max(c, 2 * D * mu / (std::max(rho_min, 1e-300) * h_));
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    const double* m = P.col(P.mass) + batch.begin;
    const double* V = P.col(P.volume) + batch.begin;
    const int por = suspension_ ? P.find("porosity") : -1;
    const double* n = P.has(por) ? P.col(por) + batch.begin : nullptr;
    for (int p = 0; p < batch.count; ++p) {
      double d[3][3], w[3][3];
      strain_and_spin<D>(batch.L, kBlock, size_t(p), 1.0, d, w);  // rates: D = sym(L)
      const double pr = pressure(m[p] / V[p]);
      const double tr3 = (d[0][0] + d[1][1] + d[2][2]) / 3;
      const double c = n ? std::clamp(1 - n[p], 0.0, 1.0) : 0.0;
      const double two_mu = 2 * mu_ * (n ? 1 + 2.5 * c + 5.2 * c * c : 1.0);
      s[0][p] = -pr + two_mu * (d[0][0] - tr3);
      s[1][p] = -pr + two_mu * (d[1][1] - tr3);
      s[2][p] = -pr + two_mu * (d[2][2] - tr3);
      if constexpr (NS > 3) s[3][p] = two_mu * d[0][1];
      if constexpr (NS > 5) s[4][p] = two_mu * d[1][2], s[5][p] = two_mu * d[0][2];
    }
  }

  /// Stored energy m int_{rho0}^{rho} p(r) / r^2 dr of the equation of state (cutoff included):
  /// K m (ln(rho/rho0)/rho0 + 1/rho - 1/rho0), plus p_c m (1/rho - 1/rho_c) below the cavitation
  /// density rho_c = rho0 (1 - p_c/K).
  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    const double* m = P.col(P.mass);
    const double* V = P.col(P.volume);
    const double rho_c = rho0_ * (1 + p_min_ / K_);  // -inf without a cutoff
    auto eos = [&](double r) { return K_ * (std::log(r / rho0_) / rho0_ + 1 / r - 1 / rho0_); };
    double sum = 0;
    for (size_t i = b; i < e; ++i) {
      const double rho = m[i] / V[i];
      sum += m[i] * (rho >= rho_c ? eos(rho) : eos(rho_c) - p_min_ * (1 / rho - 1 / rho_c));
    }
    return sum;
  }

 private:
  double K_, mu_, rho0_, p_min_;
  bool suspension_;
  double h_ = 0;
};

LOAM_REGISTER(Material, NewtonianFluid)

}  // namespace loam
