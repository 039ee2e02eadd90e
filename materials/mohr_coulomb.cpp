// Mohr-Coulomb elastoplasticity (perfectly plastic, non-associated) with linear isotropic
// elasticity, hypoelastic with the Jaumann stress rate, and an optional tension cutoff.
//
// Sign convention: Cauchy stress, TENSION POSITIVE (as every loam material), Voigt order
// xx yy zz xy yz xz; 1D stores xx yy zz (laterally confined), 2D is plane strain and stores
// xx yy zz xy, 3D stores all six. Principal stresses are ordered s1 >= s2 >= s3 (s1 the most
// tensile, s3 the most compressive). Angles phi (friction) and psi (dilation) are in degrees.
//
// Update per step, with d = sym(L) dt and w = skew(L) dt:
//   1. sigma_tr = sigma + (w sigma - sigma w) + lambda tr(d) I + 2 G d        (elastic trial)
//   2. eigen-decomposition sigma_tr = V diag(s1, s2, s3) V^T (Eigen SelfAdjointEigenSolver)
//   3. closed-form return mapping in principal stresses onto the Mohr-Coulomb planes, edges,
//      apex and the tension cutoff: MohrCoulombSurface in mohr_coulomb_return.hpp (shared with
//      strain_softening_mc), where the algorithm is described.
//   4. sigma = V diag(s) V^T.
// State: plastic_strain_eq += sqrt(2/3 e^p : e^p), e^p the deviatoric part of the principal
// plastic strain increment.
#include <cmath>
#include <limits>

#include "framework/diagnostics.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "materials/isotropic_elasticity.hpp"
#include "materials/mohr_coulomb_return.hpp"
#include "plausible.hpp"

namespace loam {

template <int D>
class MohrCoulomb : public Material<D> {
 public:
  static constexpr const char* name = "mohr_coulomb";
  static constexpr const char* summary =
      "Mohr-Coulomb plasticity (c, phi, psi, tension cutoff), linear elastic, Jaumann rate; "
      "exact principal-stress return (plane, edges, apex)";
  static Schema schema() {
    Schema s = isotropic_elastic_schema(true);
    s.real("c", "Pa", "cohesion").required().non_negative();
    plausible_angle(s.real("phi", "deg", "friction angle").required().min(0).below(90));
    add_dilation_angle(s);
    s.real("tension_cutoff", "Pa",
           "largest principal stress (tension positive); default: the Mohr-Coulomb apex "
           "c/tan(phi), none when phi = 0")
        .non_negative();
    return s;
  }

  explicit MohrCoulomb(const Params& p)
      : E_(p.real("E")),
        nu_(p.real("nu")),
        rho_(p.real("density")),
        c_(p.real("c")),
        phi_(p.real("phi")),
        psi_(p.real("psi")),
        cutoff_(p.has("tension_cutoff") ? p.real("tension_cutoff")
                                        : std::numeric_limits<double>::infinity()),
        surface_(E_, nu_, c_, phi_, psi_, cutoff_) {
    G_ = E_ / (2 * (1 + nu_));
    lambda_ = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_));
    M_ = lambda_ + 2 * G_;
  }

  double density() const override { return rho_; }

  void setup(Simulation<D>& sim, int m, Diagnostics&) override {
    const int set = sim.body_set(m);  // state fields live in the set of the body
    eq_ = sim.request_field(plastic_strain_eq_field(), set);
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    return p_wave_speed(P, b, e, M_);  // elastic P-wave speed bounds the plastic one
  }

  /// c / F and tan(phi) / F; psi is kept unless it would exceed the reduced phi (psi <= phi);
  /// a given tension cutoff is divided by F (the default, the apex c / tan(phi), is unchanged).
  std::unique_ptr<Material<D>> reduced(double F) const override {
    auto m = std::make_unique<MohrCoulomb>(*this);
    m->c_ = c_ / F;
    m->phi_ = reduced_friction_angle(phi_, F);
    m->psi_ = std::min(psi_, m->phi_);
    m->cutoff_ = cutoff_ / F;
    m->surface_ = MohrCoulombSurface(E_, nu_, m->c_, m->phi_, m->psi_, m->cutoff_);
    return m;
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    double* eq = eq_ >= 0 ? P.col(eq_) + batch.begin : nullptr;
    for (int p = 0; p < batch.count; ++p) {
      Eigen::Matrix3d tr = jaumann_trial_stress<D>(s, batch, p, lambda_, G_);
      double deq = 0;
      if (surface_.return_map(tr, deq) && eq) eq[p] += deq;
      store_stress<D>(s, p, tr);
    }
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    return isotropic_elastic_energy(P, b, e, E_, nu_);
  }

 private:
  double E_, nu_, rho_, G_ = 0, lambda_ = 0, M_ = 0;
  double c_, phi_, psi_, cutoff_;  // Pa, degrees, degrees, Pa
  MohrCoulombSurface surface_;
  int eq_ = -1;
};

LOAM_REGISTER(Material, MohrCoulomb)

}  // namespace loam
