// Reference: the depth of a scour pit along a vertical jet axis (the water jet on a sand bed of
// Liang, Zhao & Martinelli, "MPM simulations of the interaction between water jet and soil bed",
// seed 003; docs/verification.md E). It measures: the published result is a trend (the pit
// deepens about linearly in the first second, deeper for a faster jet), so the metric is the
// depth itself, recorded as a time series (verify.series in summary.json and verify.csv).
//   scour_depth(t) = bed_level - z_top(t),   z_top the highest particle of the bed body inside
//   the strip |x_d - axis_d| <= half_width (d < D - 1: the horizontal axes; z the last axis)
// counting only grains in contact (a `contact` field of the scheme equal to 1, when it has one:
// suspended, fluidised grains thrown up by the jet are not the bed). bed_level defaults to z_top
// at set-up, so the depth starts at 0. Sampled after the first step, then each
// time the run passes a multiple of `every` seconds, and at the end; NaN when the strip holds
// no grain of the bed.
// Metrics: scour_depth (at the end), scour_depth_max (over the samples).
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class ScourDepth : public Reference<D> {
 public:
  static constexpr const char* name = "scour_depth";
  static constexpr const char* summary =
      "depth of the scour pit of a bed along a vertical axis over time (the water jet of Liang, "
      "Zhao & Martinelli, docs/verification.md E)";
  static Schema schema() {
    Schema s;
    s.text("body", "the bed (default: the first body)");
    s.real_list("axis", "m",
                "the jet axis: its coordinates along the horizontal axes (D - 1 values: x in 2D, "
                "x and y in 3D)")
        .required();
    s.real("half_width", "m", "half-width of the strip (2D) or square (3D) around the axis")
        .def("0.5")
        .positive();
    s.real("every", "s", "sampling interval").def("0.1").positive();
    s.real("bed_level", "m",
           "the bed surface the depth is measured from (default: the highest grain in the strip "
           "at the start)");
    return s;
  }
  explicit ScourDepth(const Params& p)
      : params_(p),
        axis_(p.vec("axis")),
        half_width_(p.real("half_width")),
        clock_{p.real("every")} {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (int(axis_.size()) != D - 1) {
      diag.error(params_.where("axis"), params_.path("axis"),
                 "give " + std::to_string(D - 1) + " coordinate(s): the horizontal axes of a " +
                     std::to_string(D) + "D run");
      return;
    }
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    contact_ = sim.particles_of_body(body_).find("contact");
    bed_ = params_.has("bed_level") ? params_.real("bed_level") : strip_top(sim);
    if (!std::isfinite(bed_))
      diag.error(params_.where("axis"), params_.path("axis"),
                 "no particle of the bed lies within half_width of the axis");
  }

  void sample(Simulation<D>& sim) override {
    if (!clock_.due(sim.time)) return;
    const double top = strip_top(sim);
    time_.push_back(sim.time);
    depth_.push_back(std::isfinite(top) ? bed_ - top : std::nan(""));
  }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    if (time_.empty() || time_.back() < sim.time) {
      clock_.restart();  // the end of the run is always sampled
      sample(sim);
    }
    double worst = -std::numeric_limits<double>::infinity();
    for (double d : depth_)
      if (std::isfinite(d)) worst = std::max(worst, d);
    return {{"scour_depth", depth_.back()},
            {"scour_depth_max", std::isfinite(worst) ? worst : std::nan("")},
            {"bed_level", bed_}};
  }

  std::vector<std::pair<std::string, std::vector<double>>> series() const override {
    return {{"time", time_}, {"scour_depth", depth_}};
  }
  /// The strip's highest grain is a maximum over the ranks.
  bool runs_on_ranks() const override { return true; }

  bool save_state(std::vector<double>& s) const override {
    s = {clock_.next};
    s.insert(s.end(), time_.begin(), time_.end());
    s.insert(s.end(), depth_.begin(), depth_.end());
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    clock_.next = s.at(0);
    const long n = long(s.size() - 1) / 2;
    time_.assign(s.begin() + 1, s.begin() + 1 + n);
    depth_.assign(s.begin() + 1 + n, s.end());
  }

 private:
  /// The highest grain of the bed in contact within the strip (-inf if none).
  double strip_top(const Simulation<D>& sim) const {
    const Particles<D>& P = sim.particles_of_body(body_);
    double top = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_ || (P.has(contact_) && P.col(contact_)[i] == 0)) continue;
      bool in = true;
      for (int d = 0; d < D - 1; ++d)
        in = in && std::fabs(P.col(P.position, d)[i] - axis_[size_t(d)]) <= half_width_;
      if (in) top = std::max(top, P.col(P.position, D - 1)[i]);
    }
    return sim.ranks->max(top);  // over the ranks (identity serially)
  }

  Params params_;
  std::vector<double> axis_;
  double half_width_, bed_ = 0;
  SampleClock clock_;
  int body_ = -1, contact_ = -1;
  std::vector<double> time_, depth_;
};

LOAM_REGISTER(Reference, ScourDepth)

}  // namespace loam
