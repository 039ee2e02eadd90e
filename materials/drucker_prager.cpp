// Drucker-Prager elastoplasticity (perfectly plastic, non-associated) with linear isotropic
// elasticity, hypoelastic with the Jaumann stress rate, a tension cutoff on the mean stress and
// the apex returned exactly. The smooth cone most MPM reproductions of granular flows use.
//
// Sign convention: Cauchy stress, TENSION POSITIVE; p = tr(sigma)/3 (tension positive), s the
// deviator, J2 = s:s/2. Voigt storage as every loam material (docs/plugins.md).
//
// Yield and plastic potential (de Souza Neto, Peric & Owen 2008, section 6.4.6):
//   f = sqrt(J2) + eta p - xi c,     g = sqrt(J2) + eta_bar p,
// eta, xi from phi and eta_bar from psi, matched to Mohr-Coulomb (`match`):
//   compression (outer cone, through MC's triaxial-compression corners; the default):
//     eta = 6 sin phi / (sqrt3 (3 - sin phi)),  xi = 6 cos phi / (sqrt3 (3 - sin phi));
//   extension (inner cone, through the triaxial-extension corners): 3 + sin phi instead;
//   plane_strain (the plane-strain strength of MC with the same dilation angle): at a plane-
//     strain limit state the out-of-plane plastic strain rate vanishes, s_zz = -(2/3) eta_bar
//     sqrt(J2), so sqrt(J2) = t / sqrt(1 - eta_bar^2/3) and p = s_m - eta_bar sqrt(J2)/3, with
//     t = (sigma_1 - sigma_3)/2 and s_m = (sigma_1 + sigma_3)/2 in the plane. f = 0 is then MC's
//     t = c cos phi - s_m sin phi when
//       eta_bar = 3 sin psi / sqrt(9 + 3 sin^2 psi)   (the in-plane dilation angle is psi),
//       eta = sin phi / (sqrt(1 - eta_bar^2/3) + eta_bar sin phi / 3),
//       xi = cos phi (1 - eta eta_bar / 3) / sqrt(1 - eta_bar^2/3).
//     Associated (psi = phi) this is eta = 3 tan phi / sqrt(9 + 12 tan^2 phi), xi = 3 /
//     sqrt(9 + 12 tan^2 phi) (de Souza Neto et al. 2008, section 6.4.6); psi = 0 gives eta =
//     sin phi, xi = cos phi. Matching the associated cone for psi < phi overestimates the
//     strength: simple shear at phi = 30, psi = 0 gave tau/sigma_n 0.4799 against MC's 0.5.
// With compression matching a drained triaxial compression fails at MC's peak and dilates at
// d eps_v / d eps_1 = -2 sin psi / (1 - sin psi), as MC does (tests/test_drucker_prager.cpp).
//
// Return mapping, exact for linear elasticity (K bulk, G shear modulus), from the elastic trial
// (p_tr, s_tr):
//   cone:   dg = f_tr / (G + K eta eta_bar);  s = (1 - G dg / sqrt(J2_tr)) s_tr,
//           p = p_tr - K eta_bar dg; accepted if sqrt(J2_tr) - G dg >= 0 and p <= T;
//   cap:    p = T, s = s_tr (associated flow on the plane p = T), if p_tr > T and
//           sqrt(J2_tr) <= xi c - eta T;
//   corner: p = T, sqrt(J2) = xi c - eta T, with both multipliers >= 0:
//           dg1 = (sqrt(J2_tr) - (xi c - eta T)) / G, dg2 = (p_tr - T) / K - eta_bar dg1.
// T is the tension cutoff, at most the apex xi c / eta (the default; none when phi = 0). With
// T at the apex the corner is the apex return: p = xi c / eta, s = 0.
// State: plastic_strain_eq += dg1 / sqrt(3) = sqrt(2/3 e^p : e^p), e^p = dg1 s / (2 sqrt(J2)).
#include <algorithm>
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

/// The Drucker-Prager cone matched to Mohr-Coulomb (see the header): slope eta and cohesion
/// factor xi of f = sqrt(J2) + eta p - xi c, and eta_bar of g = sqrt(J2) + eta_bar p, for
/// phi and psi in degrees.
struct DruckerPragerCone {
  double eta, xi, eta_bar;
  static DruckerPragerCone matched(double phi_deg, double psi_deg, const std::string& match) {
    const double a = phi_deg * M_PI / 180.0, s = std::sin(a), c = std::cos(a);
    const double sp = std::sin(psi_deg * M_PI / 180.0);
    if (match == "plane_strain") {
      const double eta_bar = 3 * sp / std::sqrt(9 + 3 * sp * sp);
      const double r = std::sqrt(1 - eta_bar * eta_bar / 3);
      const double eta = s / (r + eta_bar * s / 3);
      return {eta, c * (1 - eta * eta_bar / 3) / r, eta_bar};
    }
    const double den = std::sqrt(3.0) * (match == "extension" ? 3 + s : 3 - s);
    const double den_psi = std::sqrt(3.0) * (match == "extension" ? 3 + sp : 3 - sp);
    return {6 * s / den, 6 * c / den, 6 * sp / den_psi};
  }
};

template <int D>
class DruckerPrager : public Material<D> {
 public:
  static constexpr const char* name = "drucker_prager";
  static constexpr const char* summary =
      "Drucker-Prager plasticity (cone matched to Mohr-Coulomb in compression, extension or "
      "plane strain; non-associated; tension cutoff), linear elastic, Jaumann rate; exact "
      "return to the cone, the cutoff and the apex";
  static Schema schema() {
    Schema s = isotropic_elastic_schema(true);
    s.real("c", "Pa", "cohesion (Mohr-Coulomb's, turned into the cone's by `match`)")
        .required()
        .non_negative();
    plausible_angle(
        s.real("phi", "deg", "friction angle (Mohr-Coulomb's)").required().min(0).below(90));
    add_dilation_angle(s);
    s.choice("match", {"compression", "extension", "plane_strain"},
             "which Mohr-Coulomb states the cone passes through: compression (outer cone, "
             "triaxial compression exact), extension (inner cone, triaxial extension exact) or "
             "plane_strain (Mohr-Coulomb's plane-strain strength for the given psi)")
        .def("compression");
    s.real("tension_cutoff", "Pa",
           "largest mean stress p = tr(sigma)/3 (tension positive); default: the cone's apex "
           "xi c / eta, none when phi = 0")
        .non_negative();
    return s;
  }

  explicit DruckerPrager(const Params& p)
      : E_(p.real("E")),
        nu_(p.real("nu")),
        rho_(p.real("density")),
        c_(p.real("c")),
        phi_(p.real("phi")),
        psi_(p.real("psi")),
        match_(p.text("match")),
        given_cutoff_(p.has("tension_cutoff") ? p.real("tension_cutoff")
                                              : std::numeric_limits<double>::infinity()) {
    G_ = E_ / (2 * (1 + nu_));
    K_ = E_ / (3 * (1 - 2 * nu_));
    lambda_ = K_ - 2 * G_ / 3;
    set_strength(c_, phi_, psi_, given_cutoff_);
  }

  double density() const override { return rho_; }

  void setup(Simulation<D>& sim, int m, Diagnostics&) override {
    eq_ = sim.request_field(plastic_strain_eq_field(), sim.body_set(m));
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    return p_wave_speed(P, b, e, lambda_ + 2 * G_);  // the elastic wave bounds the plastic one
  }

  /// c / F and tan(phi) / F (the Mohr-Coulomb parameters, then matched again); psi kept unless
  /// it would exceed the reduced phi; a given tension cutoff divided by F.
  std::unique_ptr<Material<D>> reduced(double F) const override {
    auto m = std::make_unique<DruckerPrager>(*this);
    const double phi = reduced_friction_angle(phi_, F);
    m->set_strength(c_ / F, phi, std::min(psi_, phi), given_cutoff_ / F);
    return m;
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    double* eq = eq_ >= 0 ? P.col(eq_) + batch.begin : nullptr;
    for (int p = 0; p < batch.count; ++p) {
      Eigen::Matrix3d t = jaumann_trial_stress<D>(s, batch, p, lambda_, G_);
      const double deq = return_map_drucker_prager(t);
      if (eq) eq[p] += deq;
      store_stress<D>(s, p, t);
    }
  }

  double strain_energy(const Particles<D>& P, size_t b, size_t e) const override {
    return isotropic_elastic_energy(P, b, e, E_, nu_);
  }

 private:
  void set_strength(double c, double phi, double psi, double cutoff) {
    const auto f = DruckerPragerCone::matched(phi, psi, match_);
    eta_ = f.eta;
    xi_c_ = f.xi * c;
    eta_bar_ = f.eta_bar;
    const double apex = eta_ > 0 ? xi_c_ / eta_ : std::numeric_limits<double>::infinity();
    cutoff_ = std::min(cutoff, apex);
  }

  /// Return the trial stress t onto the cone, the cutoff plane or their corner (the header's
  /// algorithm); the equivalent plastic deviatoric strain increment.
  double return_map_drucker_prager(Eigen::Matrix3d& t) const {
    const double p_tr = t.trace() / 3;
    Eigen::Matrix3d s = t;
    s.diagonal().array() -= p_tr;
    const double q_tr = std::sqrt(0.5 * (s.array() * s.array()).sum());  // sqrt(J2)
    const double f = q_tr + eta_ * p_tr - xi_c_;
    if (f <= 0 && p_tr <= cutoff_) return 0;  // elastic
    if (f > 0) {                              // the cone
      const double dg = f / (G_ + K_ * eta_ * eta_bar_);
      const double q = q_tr - G_ * dg, p = p_tr - K_ * eta_bar_ * dg;
      if (q >= 0 && p <= cutoff_) {
        set(t, s, q_tr > 0 ? q / q_tr : 0.0, p);
        return dg / std::sqrt(3.0);
      }
    }
    const double q_corner = xi_c_ - eta_ * cutoff_;  // the cone's sqrt(J2) at p = T (>= 0)
    if (q_tr <= q_corner) {                          // the cutoff plane alone: s unchanged
      set(t, s, 1.0, cutoff_);
      return 0;
    }
    const double dg1 = (q_tr - q_corner) / G_;  // the corner (the apex when T is the apex)
    set(t, s, q_corner / q_tr, cutoff_);
    return dg1 / std::sqrt(3.0);
  }

  /// t = scale s + p I.
  static void set(Eigen::Matrix3d& t, const Eigen::Matrix3d& s, double scale, double p) {
    t = scale * s;
    t.diagonal().array() += p;
  }

  double E_, nu_, rho_, G_ = 0, K_ = 0, lambda_ = 0;
  double c_, phi_, psi_;  // Mohr-Coulomb's (Pa, degrees), for reduced()
  std::string match_;
  double given_cutoff_;
  double eta_ = 0, xi_c_ = 0, eta_bar_ = 0, cutoff_ = 0;
  int eq_ = -1;
};

LOAM_REGISTER(Material, DruckerPrager)

}  // namespace loam
