// Isotropic linear elasticity, hypoelastic with the Jaumann stress rate:
//   sigma^{n+1} = sigma^n + (w sigma - sigma w) + lambda tr(d) I + 2 G d,
// d = sym(L) dt, w = skew(L) dt. Tension positive. 2D is plane strain (sigma_zz from lambda tr d),
// 1D is laterally confined (sigma_yy = sigma_zz = lambda tr d), as in VERIFICATION.md A.
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"

namespace loam {

template <int D>
class LinearElastic : public Material<D> {
 public:
  static constexpr const char* name = "linear_elastic";
  static constexpr const char* summary =
      "isotropic linear elasticity, Jaumann rate (large rotations)";
  static Schema schema() {
    Schema s;
    s.real("E", "Pa", "Young's modulus").required().positive();
    s.real("nu", "-", "Poisson's ratio").required().above(-1).below(0.5);
    s.real("density", "kg/m^3", "mass density").required().positive();
    return s;
  }
  explicit LinearElastic(const Params& p)
      : E_(p.real("E")), nu_(p.real("nu")), rho_(p.real("density")) {
    G_ = E_ / (2 * (1 + nu_));
    lambda_ = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_));
    M_ = lambda_ + 2 * G_;  // constrained (P-wave) modulus
  }

  double density() const override { return rho_; }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    return p_wave_speed(P, b, e, M_);
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    for (int p = 0; p < batch.count; ++p)
      jaumann_elastic_update<D>(s, batch.L, kBlock, size_t(p), batch.dt, lambda_, 2 * G_);
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    return isotropic_elastic_energy(P, b, e, E_, nu_);
  }

 private:
  double E_, nu_, rho_, G_, lambda_, M_;
};

LOAM_REGISTER(Material, LinearElastic)

}  // namespace loam
