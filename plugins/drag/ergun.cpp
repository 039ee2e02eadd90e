// Ergun drag (docs/verification.md D; Liang, Zhao & Martinelli, "MPM simulations of the
// interaction between water jet and soil bed", seed 003): laminar Kozeny-Carman part plus the
// inertial (Forchheimer) part, per unit mixture volume (framework/drag.hpp has the convention)
//     Q = n^2 (mu_w / kappa + n rho_w F / sqrt(kappa) |w - v|),
//     kappa = d^2 n^3 / (A (1 - n)^2)   (Kozeny-Carman, from the CURRENT porosity n),
//     F = B / (A^(1/2) n^(3/2)).
// Substituting kappa and F, the square roots cancel and the batch evaluates the equivalent
//     Q = A mu_w (1 - n)^2 / (d^2 n) + B rho_w (1 - n) |w - v| / d,
// which with the flux U = n (w - v) and Q (w - v) = -n grad(p) is the classical Ergun (1952)
// pressure gradient -grad(p) = A mu (1-n)^2 U / (n^3 d^2) + B rho (1-n) |U| U / (n^3 d).
// Limits: Q -> 0 as n -> 1 (no skeleton), Q -> infinity as n -> 0; the scheme keeps n in (0, 1).
// The -p_w grad(n) term of the Ergun force is the scheme's (see framework/drag.hpp).
#include <cmath>

#include "framework/drag.hpp"
#include "framework/registry.hpp"

namespace loam {

template <int D>
class Ergun : public Drag<D> {
 public:
  static constexpr const char* name = "ergun";
  static constexpr const char* summary =
      "Ergun drag: Kozeny-Carman permeability of the current porosity + inertial term";
  static Schema schema() {
    Schema s;
    s.real("grain_diameter", "m", "representative grain diameter d (fine sand ~2e-4)")
        .required()
        .positive();
    s.real("A", "-", "Ergun/Kozeny-Carman viscous constant (150; Carman 180)")
        .def("150")
        .positive();
    s.real("B", "-", "Ergun inertial constant (1.75)").def("1.75").non_negative();
    s.real("viscosity", "Pa s", "dynamic viscosity of the pore water mu_w (1e-3 at 20 C)")
        .def("1.0e-3")
        .positive();
    s.real("density", "kg/m^3", "density of the pore water rho_w").def("1000").positive();
    s.real("gravity", "m/s^2",
           "g in gamma_w = rho_w g, used only to report the hydraulic conductivity k = kappa "
           "gamma_w / mu_w")
        .def("9.81")
        .positive();
    return s;
  }

  explicit Ergun(const Params& p)
      : d_(p.real("grain_diameter")),
        A_(p.real("A")),
        B_(p.real("B")),
        mu_(p.real("viscosity")),
        rho_(p.real("density")),
        gamma_(rho_ * p.real("gravity")),
        a_(A_ * mu_ / (d_ * d_)),
        b_(B_ * rho_ / d_) {}

  void coefficient(size_t count, const double* n, const double* speed, double* Q) const override {
    const double a = a_, b = b_;
    if (!speed) {  // laminar limit
#pragma omp simd
      for (size_t i = 0; i < count; ++i) Q[i] = a * (1 - n[i]) * (1 - n[i]) / n[i];
      return;
    }
#pragma omp simd
    for (size_t i = 0; i < count; ++i) {
      const double s = 1 - n[i];
      Q[i] = s * (a * s / n[i] + b * speed[i]);
    }
  }
  bool speed_dependent() const override {
    return B_ > 0;
  }
  /// k = kappa(n) gamma_w / mu_w with the Kozeny-Carman kappa.
  double hydraulic_conductivity(double n) const override {
    return permeability(n) * gamma_ / mu_;
  }
  double water_density() const override {
    return rho_;
  }
  double water_viscosity() const override {
    return mu_;
  }
  /// Kozeny-Carman intrinsic permeability (m^2).
  double permeability(double n) const {
    return d_ * d_ * n * n * n / (A_ * (1 - n) * (1 - n));
  }

 private:
  double d_, A_, B_, mu_, rho_, gamma_, a_, b_;
};

LOAM_REGISTER(Drag, Ergun)

}  // namespace loam
