// Darcy drag (docs/verification.md D): linear in the relative velocity, per unit mixture volume
//     Q = n^2 mu_w / kappa = n^2 gamma_w / k,   k = kappa gamma_w / mu_w,   gamma_w = rho_w g,
// with n the current porosity (framework/drag.hpp has the convention; the per-unit-water-volume
// coefficient n gamma_w / k of the FEM-and-MPM comparison of large-strain consolidation, seed
// 001 in docs/verification.md, is Q / n). Given either the hydraulic conductivity k (m/s,
// then mu_w only enters hydraulic <-> intrinsic conversions) or the intrinsic permeability kappa
// (m^2), never both. Either way k and kappa are constants: Q varies with n only through n^2.
#include <cmath>

#include "framework/drag.hpp"
#include "framework/registry.hpp"

namespace loam {

template <int D>
class Darcy : public Drag<D> {
 public:
  static constexpr const char* name = "darcy";
  static constexpr const char* summary =
      "Darcy drag Q = n^2 gamma_w / k = n^2 mu_w / kappa per unit mixture volume";
  static Schema schema() {
    Schema s;
    s.real("hydraulic_conductivity", "m/s",
           "Darcy hydraulic conductivity k (sand 1e-5-1e-2, clay 1e-11-1e-8); give this or "
           "intrinsic_permeability")
        .positive();
    s.real("intrinsic_permeability", "m^2",
           "intrinsic permeability kappa = k mu_w / gamma_w (1e-3 m/s ~ 1e-10 m^2); give this or "
           "hydraulic_conductivity")
        .positive();
    s.real("viscosity", "Pa s", "dynamic viscosity of the pore water mu_w (1e-3 at 20 C)")
        .def("1.0e-3")
        .positive();
    s.real("density", "kg/m^3", "density of the pore water rho_w").def("1000").positive();
    s.real("gravity", "m/s^2",
           "g in gamma_w = rho_w g, the unit weight that defines k (a material constant, not the "
           "run's gravity, which may be zero)")
        .def("9.81")
        .positive();
    s.check([](const Params& p, Diagnostics& d) {
      const bool k = p.has("hydraulic_conductivity"), kappa = p.has("intrinsic_permeability");
      if (k && kappa)
        d.error(p.where("intrinsic_permeability"), p.path("intrinsic_permeability"),
                "give either hydraulic_conductivity or intrinsic_permeability, not both");
      else if (!k && !kappa)
        d.error(p.where(), p.path(),
                "missing the permeability: give hydraulic_conductivity (m/s) or "
                "intrinsic_permeability (m^2)");
    });
    return s;
  }

  explicit Darcy(const Params& p)
      : mu_(p.real("viscosity")), rho_(p.real("density")), gamma_(rho_ * p.real("gravity")) {
    // One constant c with Q = c n^2, taken from whichever permeability was given.
    if (p.has("hydraulic_conductivity")) {
      k_ = p.real("hydraulic_conductivity");
      c_ = gamma_ / k_;
    } else {
      const double kappa = p.real("intrinsic_permeability");
      c_ = mu_ / kappa;
      k_ = kappa * gamma_ / mu_;
    }
  }

  void coefficient(size_t count, const double* n, const double*, double* Q) const override {
    const double c = c_;
#pragma omp simd
    for (size_t i = 0; i < count; ++i) Q[i] = c * n[i] * n[i];
  }
  double hydraulic_conductivity(double) const override {
    return k_;
  }
  double water_density() const override {
    return rho_;
  }
  double water_viscosity() const override {
    return mu_;
  }

 private:
  double mu_, rho_, gamma_, k_ = 0, c_ = 0;
};

LOAM_REGISTER(Drag, Darcy)

}  // namespace loam
