// Strain-softening Mohr-Coulomb: the mohr_coulomb model (linear isotropic elasticity,
// hypoelastic with the Jaumann rate, non-associated Mohr-Coulomb plasticity, optional tension
// cutoff) whose cohesion c, friction angle phi and dilation angle psi fall linearly from their
// peak to their residual values as the equivalent plastic deviatoric strain
//   eps_q^p = sum over steps of sqrt(2/3 e^p : e^p)     (state field softening_strain)
// grows from softening_start to softening_end (docs/verification.md B; the slope seed uses this):
//   t = clamp((eps_q^p - softening_start) / (softening_end - softening_start), 0, 1),
//   c = c_peak + t (c_residual - c_peak), and likewise phi and psi (in degrees).
// Below softening_start the model is perfectly plastic at peak strength, beyond softening_end
// perfectly plastic at residual strength. The state is its own field, softening_strain: the
// shared output measure plastic_strain_eq accumulates the same increments but a stage's
// `reset: [plastic_strain]` zeroes it, and that must not heal a softened material.
//
// Sign convention: Cauchy stress, TENSION POSITIVE, Voigt xx yy zz xy yz xz (1D: xx yy zz,
// laterally confined; 2D: plane strain, xx yy zz xy; 3D: all six). Angles in degrees.
//
// Update per step (d = sym(L) dt, w = skew(L) dt):
//   1. elastic trial sigma_tr = sigma + (w sigma - sigma w) + lambda tr(d) I + 2 G d and its
//      principal stresses (computed once per step);
//   2. if sigma_tr is admissible for the strength at the current eps_q^p = x_n: elastic;
//   3. otherwise the strength is made consistent with the plastic strain of the step: with
//      deq(x) the equivalent plastic strain increment of the exact Mohr-Coulomb return
//      (MohrCoulombSurface, mohr_coulomb_return.hpp, the same code as mohr_coulomb) from the
//      same trial onto the surface with the parameters at x, solve the scalar equation
//        r(x) = x - x_n - deq(x) = 0
//      starting from x_0 = x_n (r <= 0) and the fixed-point step x_1 = x_n + deq(x_n), then
//      secant steps kept inside the bracket of the sign changes found so far (bisection when a
//      secant step leaves it, the fixed-point step x_n + deq(x) while there is no upper bound),
//      until |r| <= 1e-12 (x_n + deq), at most 60 returns (1 when the parameters are constant
//      over the step: peak == residual, before softening_start, after softening_end; measured
//      4.6 on average per softening step on a 5000-step compression path, 15 at most, where a
//      step crosses softening_end). The stress and softening_strain += deq are those of the
//      last return: the stress is on the yield surface of parameters taken at a plastic strain
//      within 1e-12 (x_n + deq) of the new eps_q^p. With peak == residual it is mohr_coulomb,
//      bit for bit.
// Very brittle softening (a drop of strength over a strain range that is small against the
// strength over the elastic modulus) gives a local snap-back, where r(x) may have several
// roots; the solve then returns one bracketed root (after 60 returns, the last iterate).
// Regularisation (optional `characteristic_length` l_c): a softening band localises into the
// narrowest band the grid resolves, so the strain range over which the strength falls, and with
// it the energy dissipated in the band, shrinks with the resolution. That width is the cell, not
// the particle spacing: a particle's velocity gradient comes from the nodes of its cell (constant
// over the cell for linear tents, nearly so for GIMP), so the points of one cell strain alike and
// a band cannot be narrower than h, however many points a cell holds. With l_c the softening
// strains are given for a band of width l_c and scaled to the band width w = h of the grid
// (h = (h_1 ... h_D)^(1/D), the geometric mean of the cell sides): softening_start l_c / h and
// softening_end l_c / h. The displacement across the band over which the strength falls,
// (softening_end - softening_start) l_c, and the fracture energy per unit band area are then
// independent of the resolution: the crack band of Bazant & Oh (1983), whose width is one
// element (Pietruszczak & Mroz 1981). Without it the strains apply as given at every resolution
// (mesh-dependent).
#include <cmath>
#include <limits>
#include <string>

#include "framework/diagnostics.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "materials/isotropic_elasticity.hpp"
#include "materials/mohr_coulomb_return.hpp"
#include "plausible.hpp"

namespace loam {

template <int D>
class StrainSofteningMC : public Material<D> {
  using Vec3 = MohrCoulombSurface::Vec3;

 public:
  static constexpr const char* name = "strain_softening_mc";
  static constexpr const char* summary =
      "Mohr-Coulomb whose c, phi, psi soften linearly from peak to residual with the equivalent "
      "plastic deviatoric strain; linear elastic, Jaumann rate; exact principal-stress return";
  static Schema schema() {
    Schema s = isotropic_elastic_schema(true);
    s.real("c_peak", "Pa", "peak cohesion").required().non_negative();
    s.real("c_residual", "Pa", "residual cohesion (<= c_peak)").required().non_negative();
    plausible_angle(s.real("phi_peak", "deg", "peak friction angle").required().min(0).below(90));
    plausible_angle(s.real("phi_residual", "deg", "residual friction angle (<= phi_peak)")
                        .required()
                        .min(0)
                        .below(90));
    plausible_angle(
        s.real("psi_peak", "deg", "peak dilation angle (non-associated flow; <= phi_peak)")
            .required()
            .min(0)
            .below(90));
    plausible_angle(
        s.real("psi_residual", "deg", "residual dilation angle (<= psi_peak, <= phi_residual)")
            .required()
            .min(0)
            .below(90));
    s.real("softening_start", "-",
           "equivalent plastic deviatoric strain sqrt(2/3 e:e) where softening begins (peak "
           "strength below it)")
        .def("0")
        .non_negative();
    s.real("softening_end", "-",
           "equivalent plastic deviatoric strain where the residual strength is reached (> "
           "softening_start)")
        .required()
        .positive();
    s.real("tension_cutoff", "Pa",
           "largest principal stress (tension positive), constant; capped by the current apex "
           "c/tan(phi); default: the apex")
        .non_negative();
    s.real("characteristic_length", "m",
           "regularisation: the softening strains hold for a band this wide; they are scaled by "
           "characteristic_length / h, h the grid's cell size (the narrowest band it resolves; "
           "the geometric mean of the sides), so the displacement over which a band softens does "
           "not depend on the cell size or the particles per cell (default: no scaling)")
        .positive();
    s.check([](const Params& p, Diagnostics& d) {
      auto fmt = [&](const char* k) { return std::string(k) + " = " + format_number(p.real(k)); };
      for (const char* q : {"c", "phi", "psi"}) {
        const std::string peak = std::string(q) + "_peak", res = std::string(q) + "_residual";
        if (p.real(res) > p.real(peak))
          d.error(p.where(res), p.path(res),
                  "residual " + fmt(res.c_str()) + " must not exceed the peak " +
                      fmt(peak.c_str()) + " (softening only)");
      }
      for (const char* w : {"peak", "residual"}) {
        const std::string psi = std::string("psi_") + w, phi = std::string("phi_") + w;
        if (p.real(psi) > p.real(phi))
          d.error(p.where(psi), p.path(psi),
                  "dilation angle " + fmt(psi.c_str()) + " must not exceed the friction angle " +
                      fmt(phi.c_str()));
      }
      if (p.real("softening_end") <= p.real("softening_start"))
        d.error(p.where("softening_end"), p.path("softening_end"),
                fmt("softening_end") + " must exceed " + fmt("softening_start"));
    });
    return s;
  }

  explicit StrainSofteningMC(const Params& p)
      : E_(p.real("E")),
        nu_(p.real("nu")),
        rho_(p.real("density")),
        c_{p.real("c_peak"), p.real("c_residual")},
        phi_{p.real("phi_peak"), p.real("phi_residual")},
        psi_{p.real("psi_peak"), p.real("psi_residual")},
        start_(p.real("softening_start")),
        end_(p.real("softening_end")),
        cutoff_(p.has("tension_cutoff") ? p.real("tension_cutoff")
                                        : std::numeric_limits<double>::infinity()) {
    G_ = E_ / (2 * (1 + nu_));
    lambda_ = E_ * nu_ / ((1 + nu_) * (1 - 2 * nu_));
    M_ = lambda_ + 2 * G_;
    constant_ = c_[0] == c_[1] && phi_[0] == phi_[1] && psi_[0] == psi_[1];
    if (p.has("characteristic_length")) length_ = p.real("characteristic_length");
  }

  double density() const override { return rho_; }

  void setup(Simulation<D>& sim, int m, Diagnostics&) override {
    const int set = sim.body_set(m);  // state fields live in the set of the body
    eq_ = sim.request_field(plastic_strain_eq_field(), set);
    state_ = sim.request_field({"softening_strain",
                                1,
                                "-",
                                "equivalent plastic deviatoric strain the strength has softened "
                                "with (strain_softening_mc's "
                                "state; a stage's reset leaves it)",
                                {}},
                               set);
    scale_ = 1;
    if (length_ > 0) {
      double volume = 1;
      for (double h : sim.grid.cell) volume *= h;
      scale_ = length_ / std::pow(volume, 1.0 / D);
    }
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    return p_wave_speed(P, b, e, M_);  // elastic P-wave speed bounds the plastic one
  }

  /// Peak and residual strength alike: c / F, tan(phi) / F, psi capped by the reduced phi; a
  /// given tension cutoff divided by F.
  std::unique_ptr<Material<D>> reduced(double F) const override {
    auto m = std::make_unique<StrainSofteningMC>(*this);
    for (int k = 0; k < 2; ++k) {
      m->c_[k] = c_[k] / F;
      m->phi_[k] = reduced_friction_angle(phi_[k], F);
      m->psi_[k] = std::min(psi_[k], m->phi_[k]);
    }
    m->cutoff_ = cutoff_ / F;
    return m;
  }

  /// The yield surface with the parameters at equivalent plastic strain x.
  MohrCoulombSurface surface(double x) const {
    const double t =
        std::clamp((x - start_ * scale_) / (end_ * scale_ - start_ * scale_), 0.0, 1.0);
    auto at = [t](const double(&v)[2]) {
      return t == 0 ? v[0] : t == 1 ? v[1] : v[0] + t * (v[1] - v[0]);
    };
    return MohrCoulombSurface(E_, nu_, at(c_), at(phi_), at(psi_), cutoff_);
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    double* eq = P.col(eq_) + batch.begin;
    double* state = P.col(state_) + batch.begin;
    for (int p = 0; p < batch.count; ++p) {
      Eigen::Matrix3d tr = jaumann_trial_stress<D>(s, batch, p, lambda_, G_);
      const MohrCoulombSurface::Principal pr(tr);
      const double xn = state[p];
      const MohrCoulombSurface s0 = surface(xn);
      if (s0.elastic(pr.values)) {
        store_stress<D>(s, p, tr);
        continue;
      }
      Vec3 sp;
      double deq = 0;
      s0.return_principal(pr.values, sp, deq);
      if (!constant_ && xn < end_ * scale_ && xn + deq > start_ * scale_)
        consistent_return(pr.values, xn, sp, deq);
      state[p] = xn + deq;
      eq[p] += deq;
      pr.compose(sp, tr);
      store_stress<D>(s, p, tr);
    }
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    return isotropic_elastic_energy(P, b, e, E_, nu_);
  }

 private:
  /// Solve r(x) = x - xn - deq(x) = 0 (see the header comment). On entry (s, deq) is the return
  /// with the parameters at xn; on exit the return with the parameters at the root.
  void consistent_return(const Vec3& str, double xn, Vec3& s, double& deq) const {
    double lo = xn, hi = std::numeric_limits<double>::infinity();
    double x_prev = xn, r_prev = -deq;
    double x = xn + deq;
    for (int it = 0; it < 60; ++it) {
      surface(x).return_principal(str, s, deq);
      const double r = x - xn - deq;
      if (std::fabs(r) <= 1e-12 * (xn + deq)) return;
      if (r < 0)
        lo = x;
      else
        hi = x;
      double next = r != r_prev ? x - r * (x - x_prev) / (r - r_prev) : lo;
      if (!(next > lo && next < hi)) next = std::isfinite(hi) ? 0.5 * (lo + hi) : xn + deq;
      x_prev = x, r_prev = r, x = next;
    }
  }

  double E_, nu_, rho_;
  double c_[2], phi_[2], psi_[2];  // peak, residual
  double start_, end_, cutoff_;
  double length_ = 0, scale_ = 1;  // characteristic_length (0: none), l_c / h
  double G_ = 0, lambda_ = 0, M_ = 0;
  bool constant_ = false;
  int eq_ = -1, state_ = -1;  // plastic_strain_eq (output), softening_strain (state)
};

LOAM_REGISTER(Material, StrainSofteningMC)

}  // namespace loam
