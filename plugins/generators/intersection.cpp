// The particles inside every one of several regions: a quarter of a disk for a model with two
// symmetry planes (a sphere and a box), a layer cut by a slope. Its bounding box is the overlap of
// theirs.
#include <algorithm>
#include <memory>
#include <vector>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class Intersection : public Generator<D> {
 public:
  static constexpr const char* name = "intersection";
  static constexpr const char* summary =
      "the region common to all of `of` (a quarter disk: a sphere and a box)";
  static Schema schema() {
    Schema s;
    s.plugin_list("of", "generator", "the regions (at least two)").required();
    s.check([](const Params& p, Diagnostics& d) {
      if (p.list("of").size() < 2)
        d.error(p.where("of"), p.path("of"), "an intersection needs at least two regions");
    });
    return s;
  }
  explicit Intersection(const Params& p) {
    for (const Params& m : p.list("of"))
      of_.push_back(Registry::instance().create<Generator, D>(m));
  }
  std::string check() const override {
    for (size_t k = 0; k < of_.size(); ++k)
      if (std::string problem = of_[k]->check(); !problem.empty())
        return "of[" + std::to_string(k) + "]: " + problem;
    return "";
  }
  bool contains(const std::array<double, D>& x) const override {
    for (const auto& g : of_)
      if (!g->contains(x)) return false;
    return true;
  }
  std::array<double, D> lower() const override {
    auto b = of_[0]->lower();
    for (const auto& g : of_)
      for (int d = 0; d < D; ++d) b[size_t(d)] = std::max(b[size_t(d)], g->lower()[size_t(d)]);
    return b;
  }
  std::array<double, D> upper() const override {
    auto b = of_[0]->upper();
    for (const auto& g : of_)
      for (int d = 0; d < D; ++d) b[size_t(d)] = std::min(b[size_t(d)], g->upper()[size_t(d)]);
    return b;
  }

 private:
  std::vector<std::unique_ptr<Generator<D>>> of_;
};

LOAM_REGISTER(Generator, Intersection)

}  // namespace loam
