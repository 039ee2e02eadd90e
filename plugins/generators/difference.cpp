// A region minus others: the particles of `of` that lie in none of `minus` (a plate with a hole,
// rock around a borehole, a body with a tunnel). Its bounding box is that of `of`.
#include <memory>
#include <vector>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Difference : public Generator<D> {
 public:
  static constexpr const char* name = "difference";
  static constexpr const char* summary =
      "the region `of` without the regions `minus` (holes, boreholes, tunnels)";
  static Schema schema() {
    Schema s;
    s.plugin("of", "generator", "the region particles are taken from").required();
    s.plugin_list("minus", "generator", "regions left empty (at least one)").required();
    s.check([](const Params& p, Diagnostics& d) {
      if (p.list("minus").empty())
        d.error(p.where("minus"), p.path("minus"), "give at least one region to subtract");
    });
    return s;
  }
  explicit Difference(const Params& p) {
    Registry& reg = Registry::instance();
    of_ = reg.create<Generator, D>(p.section("of"));
    for (const Params& m : p.list("minus")) minus_.push_back(reg.create<Generator, D>(m));
  }
  std::string check() const override {
    if (std::string problem = of_->check(); !problem.empty()) return "of: " + problem;
    for (size_t k = 0; k < minus_.size(); ++k)
      if (std::string problem = minus_[k]->check(); !problem.empty())
        return "minus[" + std::to_string(k) + "]: " + problem;
    return "";
  }
  bool contains(const std::array<double, D>& x) const override {
    if (!of_->contains(x)) return false;
    for (const auto& m : minus_)
      if (m->contains(x)) return false;
    return true;
  }
  std::array<double, D> lower() const override { return of_->lower(); }
  std::array<double, D> upper() const override { return of_->upper(); }

 private:
  std::unique_ptr<Generator<D>> of_;
  std::vector<std::unique_ptr<Generator<D>>> minus_;
};

LOAM_REGISTER(Generator, Difference)

}  // namespace loam
