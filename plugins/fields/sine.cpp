// Sinusoidal field a * sin(k . (x - x0)), e.g. the vibrating bar's first mode
// v(x, 0) = v0 sin(pi x / 2L) (docs/verification.md A): amplitude [v0], wavenumber [pi/(2L)].
#include <cmath>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Sine : public Field<D> {
 public:
  static constexpr const char* name = "sine";
  static constexpr const char* summary = "amplitude * sin(wavenumber . (x - origin))";
  static Schema schema() {
    Schema s;
    s.vector("amplitude", "(field unit)", "amplitude of each component", kFieldComponents)
        .required();
    s.vector("wavenumber", "1/m", "wave vector k").required();
    s.vector("origin", "m", "point where the sine is zero").def("0").scalar_ok();
    return s;
  }
  explicit Sine(const Params& p)
      : a_(p.vec("amplitude")), k_(p.vec("wavenumber")), x0_(p.vec("origin")) {}
  void value(const std::array<double, D>& x, double* out) const override {
    double phase = 0;
    for (int d = 0; d < D; ++d) phase += k_[size_t(d)] * (x[size_t(d)] - x0_[size_t(d)]);
    for (size_t c = 0; c < a_.size(); ++c) out[c] = a_[c] * std::sin(phase);
  }

 private:
  std::vector<double> a_, k_, x0_;
};

LOAM_REGISTER(Field, Sine)

}  // namespace loam
