// Modified Cam Clay (Roscoe & Burland 1968): critical-state elastoplasticity with an elliptical
// yield surface, associated flow, volumetric hardening and pressure-dependent elasticity; stress
// rotated with the Jaumann rate, integrated by an implicit return mapping.
//
// Sign conventions. The framework stress is Cauchy, TENSION POSITIVE, Voigt xx yy zz xy yz xz
// (1D stores xx yy zz, 2D plane strain xx yy zz xy, 3D all six). Inside this model, as in soil
// mechanics, pressures and volumetric strains are COMPRESSION POSITIVE:
//   p' = -tr(sigma)/3,  s = sigma + p' I (deviator),  q = sqrt(3 J2) = sqrt(3/2 s:s),
//   deps_v = compression of the specific volume v = 1 + e per unit v (see below).
// The stress is treated as effective stress (dry soil, or the skeleton of a saturated one).
//
// Model:
//   yield surface   f = q^2/M^2 + p'(p' - pc) <= 0            (ellipse through p' = 0 and pc)
//   flow            associated: deps_v^p = dgamma (2p' - pc),  de^p = dgamma 3 s/M^2
//   hardening       pc = pc_n exp(v_n deps_v^p / (lambda - kappa))
//   elasticity      (p' + pm) = (p'_n + pm) exp(v_n deps_v^e / kappa),   pm = min_pressure,
//                   i.e. tangent bulk modulus K = v (p' + pm)/kappa; shear modulus G constant
//                   (parameter G) or G = 3K(1 - 2nu)/(2(1 + nu)) (parameter nu) with K taken at
//                   the start of the (sub)step, so the deviatoric return stays radial.
//   With min_pressure = 0 these are the textbook laws: the normal compression line
//   e = e_N - lambda ln p' and unloading lines e = e_k - kappa ln p' are reproduced EXACTLY
//   for any increment size. min_pressure > 0 shifts the elastic law to ln(p' + pm), so that a
//   particle at p' = 0 (a free surface, an initially stress-free body) still has a bulk
//   stiffness v pm / kappa; for p' >> pm the shift is negligible. With min_pressure = 0 a
//   particle at p' = 0 has no stiffness at all (the MCC elastic law), and the CFL wave speed
//   of such a body is zero.
//
// Volume. Each step the specific volume is updated as v_{n+1} = v_n exp(tr d) (logarithmic
// volumetric strain, d = sym(L) dt), and the constitutive volumetric strain increment is
//   deps_v = (v_n - v_{n+1})/v_n = -expm1(tr d),
// so that v_n deps_v = -dv exactly and the e-ln p' slopes above hold to round-off. (The particle
// volume is updated by the schemes with det(I + L dt); the two agree to second order per step.
// exp(tr d) is chosen because it is objective: a rigid spin changes det(I + L dt) by w^2 dt^2
// but leaves tr d = 0.)
//
// Update per particle and step, d = sym(L) dt, w = skew(L) dt:
//   1. Jaumann rotation of the previous stress: sigma += w sigma - sigma w (keeps p' exactly).
//   2. Elastic trial: p'_tr from the exact elastic law, s_tr = s_n + 2 G dev(d).
//   3. If f(p'_tr, q_tr, pc_n) <= 1e-10 pc_n^2: elastic. Otherwise backward Euler return in
//      p'-q (Borja & Lee 1990; de Souza Neto, Peric & Owen 2008, ch. 10): unknowns
//      x = deps_v^p and dgamma, with p'(x), pc(x) from the exact laws above,
//      q = q_tr/(1 + 6 G dgamma/M^2) (radial return in the deviatoric plane), and residuals
//        r1 = x - dgamma (2p' - pc),     r2 = (q^2/M^2 + p'(p' - pc))/pc_n^2,
//      solved by Newton with the analytic 2x2 Jacobian from x = dgamma = 0.
//   4. Fallback: if Newton does not converge in 40 iterations or gives a non-physical result
//      (dgamma < 0, non-finite values), the strain increment is halved and the two halves are
//      integrated in turn (recursively, up to 2^6 sub-steps). At the deepest level the return
//      is solved by a bracketed scalar iteration that cannot fail: for fixed dgamma, r1 is
//      strictly increasing in x (unique root, regula falsi); f(dgamma) goes from f_tr > 0 at
//      dgamma = 0 to -pc^2/4 < 0 as dgamma -> inf, so its root is bracketed.
//      return_mapping: bracketed uses that solver for every plastic step (for verification: the
//      two solvers agree to ~1e-13 pc). Newton stops at |f| <= 1e-12 pc^2.
//   5. An elastic domain that has vanished (pc = 0, possible only with ocr, min_pressure = 0
//      and a stress-free initial state) leaves the particle stress free.
// Wave speed: sqrt((K + 4G/3)/rho) with the largest K = v (p' + pm)/kappa of the particles at
// their current pressure (and the lowest density), so it grows as the soil is compressed.
// The e-ln p' laws do not bound v: an extreme compression can drive e below 0 (not checked).
// State fields: void_ratio e (v = 1 + e), preconsolidation_pressure pc (Pa), and
// plastic_strain_eq, the accumulated sqrt(2/3 e^p:e^p) = 2 dgamma q / M^2 per step.
// Initial state (initialize(), after set-up and whenever a driver imposes a new initial
// stress): e = e0 (or v0 - 1); pc = pc0, or pc = ocr * max(p'0, min_pressure) from each
// particle's initial mean effective stress p'0; in both cases pc is raised, if needed, so that
// the initial stress lies inside or on the yield surface (pc >= p'0 + q0^2/(M^2 p'0)).
// Strength reduction (reduced(F), docs/strength_reduction.md): the critical-state strength is
// q = M p', reduced through its friction angle as Mohr-Coulomb's: sin phi_cs = 3 M / (6 + M)
// (triaxial compression, Wood 1990, Soil Behaviour and Critical State Soil Mechanics, eq.
// 7.9), tan phi_F = tan phi_cs / F, M_F = 6 sin phi_F / (3 - sin phi_F); the state (pc, e)
// is shared. M >= 3 has no friction angle: M / F.
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/diagnostics.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "framework/tensor.hpp"
#include "plausible.hpp"

namespace loam {

namespace mcc_detail {

/// Root of fun on [lo, hi] with fun(lo) and fun(hi) of opposite signs (Illinois regula falsi,
/// with a bisection every fourth iteration so the bracket always shrinks). Stops when the
/// bracket is narrower than xtol or |fun| <= ftol.
template <class F>
double bracketed_root(F&& fun, double lo, double hi, double flo, double fhi, double xtol,
                      double ftol) {
  int side = 0;
  double x = lo;
  for (int it = 0; it < 300; ++it) {
    if (it % 4 == 3 || !(std::isfinite(flo) && std::isfinite(fhi)) || flo == fhi)
      x = 0.5 * (lo + hi);
    else
      x = (lo * fhi - hi * flo) / (fhi - flo);
    if (!(x > std::min(lo, hi) && x < std::max(lo, hi))) x = 0.5 * (lo + hi);
    const double fx = fun(x);
    if (std::fabs(fx) <= ftol || std::fabs(hi - lo) <= xtol) return x;
    if ((fx > 0) == (fhi > 0)) {
      hi = x, fhi = fx;
      if (side == -1) flo *= 0.5;
      side = -1;
    } else {
      lo = x, flo = fx;
      if (side == 1) fhi *= 0.5;
      side = 1;
    }
  }
  return x;
}

/// Material point state during an update: p' (compression +), deviator s (Voigt xx yy zz xy yz
/// xz, tensor components), specific volume, preconsolidation pressure, plastic strain.
struct State {
  double p = 0;
  double s[6] = {0, 0, 0, 0, 0, 0};
  double v = 1, pc = 0, eq = 0;
};

inline double dot6(const double (&a)[6], const double (&b)[6]) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + 2 * (a[3] * b[3] + a[4] * b[4] + a[5] * b[5]);
}

}  // namespace mcc_detail

template <int D>
class ModifiedCamClay : public Material<D> {
  using State = mcc_detail::State;

 public:
  static constexpr const char* name = "modified_cam_clay";
  static constexpr const char* summary =
      "Modified Cam Clay (critical state: elliptical yield, associated flow, e-ln p' hardening, "
      "K = v p'/kappa), Jaumann rate; implicit p'-q return with sub-stepping";
  static Schema schema() {
    Schema s;
    s.real("lambda", "-", "slope of the normal compression line in e-ln p'").required().positive();
    s.real("kappa", "-", "slope of the unloading-reloading (swelling) line in e-ln p'; < lambda")
        .required()
        .positive();
    s.real("M", "-",
           "critical state stress ratio q/p' (triaxial compression: M = 6 sin phi_cs/(3 - sin "
           "phi_cs))")
        .required()
        .positive();
    s.real("nu", "-",
           "Poisson's ratio: shear modulus G = 3K(1 - 2nu)/(2(1 + nu)) follows the pressure-"
           "dependent bulk modulus K = v (p' + min_pressure)/kappa (give nu or G)")
        .min(0)
        .below(0.5);
    s.real("G", "Pa", "constant shear modulus (give nu or G)").positive();
    s.real("e0", "-", "initial void ratio (give e0 or v0)").positive();
    s.real("v0", "-", "initial specific volume 1 + e0 (give e0 or v0)").above(1);
    s.real("pc0", "Pa", "initial preconsolidation pressure p'_c (give pc0 or ocr)").positive();
    s.real("ocr", "-",
           "isotropic overconsolidation ratio: initial p'_c = ocr * p'0, with p'0 each particle's "
           "initial mean effective stress (at least min_pressure) (give pc0 or ocr)")
        .min(1);
    plausible_density(s.real("density", "kg/m^3", "mass density").required().positive());
    s.real("min_pressure", "Pa",
           "shift of the elastic law: K = v (p' + min_pressure)/kappa, so that a particle at "
           "p' = 0 (free surface, stress-free start) keeps a bulk stiffness; 0 = textbook MCC, "
           "choose it small against the working pressures")
        .def("0")
        .non_negative();
    s.choice("return_mapping", {"newton", "bracketed"},
             "newton: backward Euler return by Newton's method, halving the strain increment "
             "when it fails; bracketed: every plastic step solved by the slower scalar iteration "
             "that cannot fail (the fallback of the deepest sub-step), for verification")
        .def("newton");
    s.check([](const Params& p, Diagnostics& d) {
      if (p.real("kappa") >= p.real("lambda"))
        d.error(p.where("kappa"), p.path("kappa"),
                "swelling slope kappa = " + format_number(p.real("kappa")) +
                    " must be smaller than the compression slope lambda = " +
                    format_number(p.real("lambda")));
      for (auto [a, b] : {std::pair{"nu", "G"}, std::pair{"e0", "v0"}, std::pair{"pc0", "ocr"}}) {
        if (p.has(a) && p.has(b))
          d.error(p.where(b), p.path(b),
                  std::string("give either '") + a + "' or '" + b + "', not both");
        else if (!p.has(a) && !p.has(b))
          d.error(p.where(), p.path(),
                  std::string("give exactly one of '") + a + "' or '" + b + "'");
      }
    });
    return s;
  }

  explicit ModifiedCamClay(const Params& p)
      : lambda_(p.real("lambda")),
        kappa_(p.real("kappa")),
        M_(p.real("M")),
        rho_(p.real("density")),
        pm_(p.real("min_pressure")),
        bracketed_(p.text("return_mapping") == "bracketed") {
    if (p.has("G")) {
      G_ = p.real("G");
    } else {
      const double nu = p.real("nu");
      g_factor_ = 1.5 * (1 - 2 * nu) / (1 + nu);
    }
    e0_ = p.has("e0") ? p.real("e0") : p.real("v0") - 1;
    if (p.has("pc0"))
      pc0_ = p.real("pc0");
    else
      ocr_ = p.real("ocr");
  }

  double density() const override { return rho_; }

  void setup(Simulation<D>& sim, int m, Diagnostics&) override {
    const int set = sim.body_set(m);  // state fields live in the set of the body
    e_ = sim.request_field({"void_ratio", 1, "-", "void ratio e (specific volume v = 1 + e)", {}},
                           set);
    pc_ = sim.request_field({"preconsolidation_pressure",
                             1,
                             "Pa",
                             "preconsolidation pressure p'_c (size of the Cam Clay yield ellipse)",
                             {}},
                            set);
    eq_ = sim.request_field(plastic_strain_eq_field(), set);
  }

  void initialize(Particles<D>& P, size_t b, size_t e) override {
    if (e_ < 0) return;
    constexpr int NS = Particles<D>::NS;
    double* ev = P.col(e_);
    double* pc = P.col(pc_);
    double* eq = P.col(eq_);
    for (size_t i = b; i < e; ++i) {
      double sv[NS];
      for (int c = 0; c < NS; ++c) sv[c] = P.col(P.stress, c)[i];
      State st = to_state(sv);
      const double q2 = 1.5 * mcc_detail::dot6(st.s, st.s);
      double c = ocr_ > 0 ? ocr_ * std::max(st.p, pm_) : pc0_;
      if (st.p > 0) c = std::max(c, st.p + q2 / (M_ * M_ * st.p));
      ev[i] = e0_;
      pc[i] = c;
      eq[i] = 0;
    }
  }

  /// M reduced through the critical-state friction angle (see the header).
  std::unique_ptr<Material<D>> reduced(double F) const override {
    auto m = std::make_unique<ModifiedCamClay>(*this);
    const double s = 3 * M_ / (6 + M_);
    if (s < 1) {
      const double sf = std::sin(std::atan(std::tan(std::asin(s)) / F));
      m->M_ = 6 * sf / (3 - sf);
    } else {
      m->M_ = M_ / F;
    }
    return m;
  }

  double wave_speed(const Particles<D>& P, size_t b, size_t e) const override {
    const double* s0 = P.col(P.stress, 0);
    const double* s1 = P.col(P.stress, 1);
    const double* s2 = P.col(P.stress, 2);
    const double* ev = P.col(e_);
    double mod = 0;
#pragma omp parallel for reduction(max : mod) schedule(static)
    for (size_t i = b; i < e; ++i) {
      const double pp = std::max(-(s0[i] + s1[i] + s2[i]) / 3 + pm_, 0.0);
      const double K = (1 + ev[i]) * pp / kappa_;
      mod = std::max(mod, K + 4.0 / 3.0 * shear_modulus(K));
    }
    return p_wave_speed(P, b, e, mod);
  }

  void update_stress(const MaterialBatch<D>& batch) override {
    constexpr int NS = Particles<D>::NS;
    Particles<D>& P = *batch.particles;
    double* s[NS];
    for (int c = 0; c < NS; ++c) s[c] = P.col(P.stress, c) + batch.begin;
    double* ev = P.col(e_) + batch.begin;
    double* pc = P.col(pc_) + batch.begin;
    double* eq = P.col(eq_) + batch.begin;
    for (int p = 0; p < batch.count; ++p) {
      double d[3][3], w[3][3], m[3][3], r[3][3];
      strain_and_spin<D>(batch.L, kBlock, size_t(p), batch.dt, d, w);
      double sv[NS];
      for (int c = 0; c < NS; ++c) sv[c] = s[c][p];
      voigt_to_matrix<NS>(sv, m);
      jaumann_rotation(w, m, r);
      double rv[6] = {m[0][0] + r[0][0], m[1][1] + r[1][1], m[2][2] + r[2][2],
                      m[0][1] + r[0][1], m[1][2] + r[1][2], m[0][2] + r[0][2]};
      State st = to_state(rv);
      st.v = 1 + ev[p];
      st.pc = pc[p];
      st.eq = eq[p];
      const double trv = d[0][0] + d[1][1] + d[2][2];
      const double de[6] = {d[0][0] - trv / 3, d[1][1] - trv / 3, d[2][2] - trv / 3,
                            d[0][1],           d[1][2],           d[0][2]};
      integrate(st, trv, de, 0);
      for (int c = 0; c < NS; ++c) s[c][p] = st.s[c] - (c < 3 ? st.p : 0.0);
      ev[p] = st.v - 1;
      pc[p] = st.pc;
      eq[p] = st.eq;
    }
  }

 private:
  /// Largest recursion depth of the sub-stepping fallback (at most 2^kMaxDepth sub-steps).
  static constexpr int kMaxDepth = 6;

  template <int N>
  static State to_state(const double (&sv)[N]) {
    State st;
    st.p = -(sv[0] + sv[1] + sv[2]) / 3;
    for (int c = 0; c < 3; ++c) st.s[c] = sv[c] + st.p;
    for (int c = 3; c < 6; ++c) st.s[c] = c < N ? sv[c] : 0.0;
    return st;
  }

  double shear_modulus(double K) const {
    return g_factor_ > 0 ? g_factor_ * K : G_;
  }

  /// Integrate the increment (trv = tr d, de = dev d), halving it while the Newton return fails.
  void integrate(State& st, double trv, const double (&de)[6], int depth) const {
    if (depth >= kMaxDepth || bracketed_) {
      increment(st, trv, de, true);
      return;
    }
    State trial = st;
    if (increment(trial, trv, de, false)) {
      st = trial;
      return;
    }
    double half[6];
    for (int c = 0; c < 6; ++c) half[c] = 0.5 * de[c];
    integrate(st, 0.5 * trv, half, depth + 1);
    integrate(st, 0.5 * trv, half, depth + 1);
  }

  /// Elastic predictor and return mapping over one (sub)increment. With robust = false the
  /// return is Newton's method and the function returns false (state unusable) when it fails;
  /// with robust = true the bracketed scalar solver is used and it always succeeds.
  bool increment(State& st, double trv, const double (&de)[6], bool robust) const {
    const double pp = std::max(st.p + pm_, 0.0);  // p' + pm of the elastic law
    const double K = st.v * pp / kappa_;
    const double G = shear_modulus(K);
    const double eps = -std::expm1(trv);  // compression +, per unit v_n
    const double a = st.v / kappa_, b = st.v / (lambda_ - kappa_);
    const double M2 = M_ * M_;
    const double p_tr = pp * std::exp(a * eps) - pm_;
    double s_tr[6];
    for (int c = 0; c < 6; ++c) s_tr[c] = st.s[c] + 2 * G * de[c];
    const double q_tr = std::sqrt(1.5 * mcc_detail::dot6(s_tr, s_tr));
    const double pc_n = st.pc;
    if (!(pc_n > 0)) {  // no elastic domain left (pc = 0): the particle carries no stress
      st.p = 0;
      for (double& c : st.s) c = 0;
      st.v *= std::exp(trv);
      return true;
    }
    const double f_tr = q_tr * q_tr / M2 + p_tr * (p_tr - pc_n);
    if (!std::isfinite(f_tr) || !std::isfinite(q_tr)) return false;
    if (f_tr <= 1e-10 * pc_n * pc_n) {
      st.p = p_tr;
      for (int c = 0; c < 6; ++c) st.s[c] = s_tr[c];
      st.v *= std::exp(trv);
      return true;
    }
    // p'(x), pc(x) of the exact laws and q(dgamma) of the radial return.
    auto P_of = [&](double x) { return pp * std::exp(a * (eps - x)) - pm_; };
    auto C_of = [&](double x) { return pc_n * std::exp(b * x); };
    const double gq = 6 * G / M2;
    double x = 0, g = 0, P = p_tr, C = pc_n;
    if (!robust) {
      const double sc = 1.0 / (pc_n * pc_n);
      bool ok = false;
      for (int it = 0; it < 40; ++it) {
        P = P_of(x), C = C_of(x);
        const double dP = -a * (P + pm_), dC = b * C;
        const double den = 1 + gq * g;
        const double Q = q_tr / den, dQ = -q_tr * gq / (den * den);
        const double r1 = x - g * (2 * P - C);
        const double f = Q * Q / M2 + P * (P - C);
        if (!std::isfinite(r1) || !std::isfinite(f)) return false;
        const double r1_scale = std::fabs(x) + std::fabs(eps) + g * (2 * std::fabs(P) + C);
        if (std::fabs(r1) <= 1e-13 * r1_scale + 1e-300 && std::fabs(f) <= 1e-12 * C * C) {
          ok = true;
          break;
        }
        const double J11 = 1 - g * (2 * dP - dC), J12 = -(2 * P - C);
        const double J21 = (dP * (2 * P - C) - P * dC) * sc, J22 = 2 * Q * dQ / M2 * sc;
        const double det = J11 * J22 - J12 * J21;
        if (!std::isfinite(det) || det == 0) return false;
        const double r2 = f * sc;
        x -= (J22 * r1 - J12 * r2) / det;
        g -= (J11 * r2 - J21 * r1) / det;
        if (!std::isfinite(x) || !std::isfinite(g) || 1 + gq * g <= 0) return false;
      }
      if (!ok || g < 0) return false;
    } else {
      // Bracketed scalar solve: x(g) from r1 = 0 (increasing in x), then f(g) = 0.
      auto x_of = [&](double gg) {
        auto h = [&](double xx) { return xx - gg * (2 * P_of(xx) - C_of(xx)); };
        const double h0 = h(0);
        if (h0 == 0) return 0.0;
        double step = std::max(std::fabs(eps), 1e-8), far = h0 < 0 ? step : -step;
        double hf = h(far);
        for (int k = 0; k < 200 && (hf < 0) == (h0 < 0); ++k) far *= 2, hf = h(far);
        return mcc_detail::bracketed_root(h, 0.0, far, h0, hf, 1e-15 * std::fabs(far), 0.0);
      };
      auto f_of = [&](double gg) {
        const double xx = x_of(gg), PP = P_of(xx), CC = C_of(xx);
        const double Q = q_tr / (1 + gq * gg);
        return (Q * Q / M2 + PP * (PP - CC)) / (CC * CC);  // relative to the current pc
      };
      double hi = std::max(std::fabs(eps), 1e-8) / pc_n, fhi = f_of(hi);
      for (int k = 0; k < 200 && !(fhi < 0); ++k) hi *= 2, fhi = f_of(hi);
      g = mcc_detail::bracketed_root(f_of, 0.0, hi, f_tr / (pc_n * pc_n), fhi, 1e-15 * hi, 1e-13);
      x = x_of(g);
      P = P_of(x), C = C_of(x);
    }
    const double den = 1 + gq * g;
    st.p = P;
    for (int c = 0; c < 6; ++c) st.s[c] = s_tr[c] / den;
    st.pc = C;
    st.v *= std::exp(trv);
    st.eq += 2 * g * (q_tr / den) / M2;
    return true;
  }

  double lambda_, kappa_, M_, rho_, pm_;
  bool bracketed_;
  double G_ = 0, g_factor_ = 0;  // constant G, or G = g_factor K
  double e0_ = 0, pc0_ = 0, ocr_ = 0;
  int e_ = -1, pc_ = -1, eq_ = -1;
};

LOAM_REGISTER(Material, ModifiedCamClay)

}  // namespace loam
