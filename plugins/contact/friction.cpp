// Coulomb friction between two bodies (Bardenhagen et al. 2000, "The material-point method for
// granular materials", eq. 25-27): where the fields a and b approach each other along the normal
// n (from a towards b), (v_a - v_cm) . n > 0 with v_cm = (m_a v_a + m_b v_b) / (m_a + m_b), the
// normal impulse stops the approach and the tangential one is limited by mu times it:
//   dv_a = -(dn n + min(mu dn, |t|) t / |t|),  dn = (v_a - v_cm) . n,  t = v_a - v_cm - dn n,
//   dv_b = -m_a / m_b dv_a
// (|t| <= mu dn: the pair sticks and both move with v_cm). Separating fields move freely, so the
// bodies part without tension. mu = 0: frictionless sliding. Told that the pair approaches
// (Approach::kFound), the same with |dn|.
#include <algorithm>
#include <cmath>

#include "framework/contact.hpp"
#include "framework/registry.hpp"

namespace loam {

template <int D>
class FrictionContact : public Contact<D> {
 public:
  static constexpr const char* name = "friction";
  static constexpr const char* summary =
      "Coulomb friction between bodies: no penetration, sliding when |tau| > mu sigma_n, free "
      "separation";
  static Schema schema() {
    Schema s;
    s.real("coefficient", "-", "Coulomb friction coefficient mu (0: frictionless)")
        .required()
        .min(0);
    add_contact_bodies_param(s);
    return s;
  }
  explicit FrictionContact(const Params& p) : Contact<D>(p), mu_(p.real("coefficient")) {}

  void exchange(double ma, double mb, double (&va)[D], double (&vb)[D], const double (&n)[D],
                Approach approach) const override {
    // v_a - v_cm = m_b / (m_a + m_b) (v_a - v_b); a rigid b (m_b infinite): v_cm = v_b.
    const double share = std::isinf(mb) ? 1.0 : mb / (ma + mb);
    double rel[D], dn = 0;
    for (int d = 0; d < D; ++d) {
      rel[d] = share * (va[d] - vb[d]);
      dn += rel[d] * n[d];
    }
    if (approach == Approach::kJudged && !(dn > 0)) return;  // separating or sliding: free
    double t[D], t2 = 0;
    for (int d = 0; d < D; ++d) {
      t[d] = rel[d] - dn * n[d];
      t2 += t[d] * t[d];
    }
    const double tlen = std::sqrt(t2);
    const double slip = tlen > 0 ? std::min(mu_ * std::fabs(dn), tlen) / tlen : 0.0;
    for (int d = 0; d < D; ++d) {
      const double dva = -(dn * n[d] + slip * t[d]);
      va[d] += dva;
      vb[d] -= ma / mb * dva;
    }
  }

 private:
  double mu_;
};

LOAM_REGISTER(Contact, FrictionContact)

}  // namespace loam
