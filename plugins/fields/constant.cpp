// Constant field value (a bare YAML list is shorthand for this).
#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Constant : public Field<D> {
 public:
  static constexpr const char* name = "constant";
  static constexpr const char* summary = "the same value everywhere";
  static Schema schema() {
    Schema s;
    s.vector("value", "(field unit)", "components of the value", kFieldComponents).required();
    return s;
  }
  explicit Constant(const Params& p) : v_(p.vec("value")) {}
  void value(const std::array<double, D>&, double* out) const override {
    for (size_t c = 0; c < v_.size(); ++c) out[c] = v_[c];
  }

 private:
  std::vector<double> v_;
};

LOAM_REGISTER(Field, Constant)
// A bare YAML list in a field-valued key means this plugin.
LOAM_REGISTER_KIND_SHORTHAND("field", "constant")

}  // namespace loam
