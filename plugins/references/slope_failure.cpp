// Reference: what a slope failure did (the large-deformation footing of the FEM-and-MPM analysis
// of a hypothetical Mohr-Coulomb slope, seed 004, and the slopes of "The Material Point Method: A
// promising computational tool in Geotechnics", seed 002; docs/slope_scenes.md). The published
// results are descriptions and a few numbers (the deposit's top height, the failure's depth and
// type, when the mass came to rest, the run-out), so the metrics are measurements of the failed
// mass, printed beside the paper's:
//   failed mass   the particles of the body whose displacement since the last displacement reset
//                 (t = 0, or a stage's `reset: [displacement]`, e.g. after the gravity stage)
//                 exceeds `moved_displacement`;
//   failure_depth the deepest point of the failed mass below the ground surface above it, both
//                 in the reset configuration (the surface of a column is its highest particle
//                 domain; a particle's depth is measured to the bottom of its domain): shallow
//                 slides have a depth small against the slope height, deep-seated ones cut
//                 below the toe (slip_base_height under the toe level);
//   runout        the front of the failed mass now (its largest x, particle domains) minus the
//                 toe's x (the slope faces +x); negative while the mass has not passed the toe;
//   deposit_top_height  the ground surface now above the body's bottom at `surface_at` (the
//                 highest particle domain in the column within half a particle spacing of it);
//                 moved_mass_top_height the highest point of the failed mass, the other reading;
//   time_to_rest  from the last reset, the end of the last sampling interval in which a
//                 particle of the failed mass moved faster than `rest_speed` on average over the
//                 interval (|x(t) - x(t - every)| / every: the motion, not the FLIP velocity,
//                 which keeps a part the grid cannot see: docs/stages.md; the rest of the body,
//                 ringing elastically without damping, does not count); NaN while the failed
//                 mass still moves at the end. time_to_90_percent: when the body's mean
//                 displacement reached 90 % of its final value (the main part of the movement).
// Lengths use particle domains of the body's initial spacing (positions +- half of it).
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/registry.hpp"
#include "framework/simulation.hpp"

namespace loam {

template <int D>
class SlopeFailure : public Reference<D> {
 public:
  static constexpr const char* name = "slope_failure";
  static constexpr const char* summary =
      "a slope failure's failed mass: depth, run-out, deposit top, time to rest (seeds 002, 004)";
  static Schema schema() {
    Schema s;
    s.text("body", "the slope (default: the first body)");
    s.real("toe", "m", "x of the slope's toe (the slope faces +x): runout = front - toe")
        .required();
    s.real("moved_displacement", "m",
           "a particle belongs to the failed mass when it has moved more than this since the "
           "last displacement reset")
        .def("0.5")
        .positive();
    s.real_list("surface_at", "m",
                "where deposit_top_height is measured: the horizontal coordinates of a vertical "
                "line (D - 1 values; e.g. the strip footing's centre)")
        .def("[]");
    s.real("every", "s", "sampling interval of the series and of the rest speed")
        .def("1")
        .positive();
    s.real("rest_speed", "m/s",
           "the body is at rest once no particle moves faster than this, averaged over a "
           "sampling interval")
        .def("1e-3")
        .positive();
    s.real("paper_deposit_top_height", "m", "a published deposit top height to print beside")
        .positive();
    s.real("paper_time_to_rest", "s", "a published time to rest to print beside").positive();
    return s;
  }
  explicit SlopeFailure(const Params& p)
      : params_(p),
        toe_(p.real("toe")),
        moved_(p.real("moved_displacement")),
        surface_at_(p.vec("surface_at")),
        rest_speed_(p.real("rest_speed")),
        clock_{p.real("every")} {}

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (D < 2) {
      diag.error(params_.where(), params_.path(), "slope_failure needs a 2D or 3D grid");
      return;
    }
    if (!surface_at_.empty() && int(surface_at_.size()) != D - 1)
      diag.error(params_.where("surface_at"), params_.path("surface_at"),
                 "give " + std::to_string(D - 1) + " coordinate(s): the horizontal axes of a " +
                     std::to_string(D) + "D run");
    body_ = sim.body_param(params_, "body", diag);
    if (body_ < 0) return;
    const Body& b = sim.bodies[size_t(body_)];
    first_id_ = b.first_id;
    count_ = b.count;
    bottom_ = b.lower[D - 1];
    for (int d = 0; d < D; ++d) half_[size_t(d)] = 0.5 * b.spacing[size_t(d)];
    x_ref_ = sim.request_displacement_reference();
    // Per particle (fields, so that they travel with a particle to another rank and into
    // checkpoints): its position at the last sample, and the last sample it moved fast.
    const int set = sim.body_set(body_);
    prev_ = sim.request_field(
        {"slope_failure_previous_position", D, "m",
         "slope_failure: the position at its last sample", Particles<D>::axis_names()},
        set);
    last_fast_ = sim.request_field(
        {"slope_failure_last_fast",
         1,
         "s",
         "slope_failure: the last sample (since the reset) the particle moved faster than "
         "rest_speed",
         {}},
        set);
    restart(sim, 0);
  }

  void sample(Simulation<D>& sim) override {
    // A stage that resets the displacement restarts the measurement (the failure begins there).
    if (sim.stage != stage_) {
      stage_ = sim.stage;
      if (stage_ >= 0 && sim.stages[size_t(stage_)].reset_displacement)
        restart(sim, sim.time - sim.dt);
    }
    if (!clock_.due(sim.time - t0_)) return;
    Particles<D>& P = sim.particles_of_body(body_);
    double umax = 0, usum = 0, vmax = 0;
    long n = 0;
    const double interval = sim.time - t_prev_;
    for (size_t i = 0; i < P.size(); ++i) {
      if (!measured(P, i)) continue;
      double u2 = 0, s2 = 0;
      for (int d = 0; d < D; ++d) {
        const double x = P.col(P.position, d)[i];
        double& prev = P.col(prev_, d)[i];
        u2 += std::pow(x - P.col(x_ref_, d)[i], 2);
        s2 += std::pow(x - prev, 2);
        prev = x;
      }
      umax = std::max(umax, std::sqrt(u2));
      usum += std::sqrt(u2);
      vmax = std::max(vmax, std::sqrt(s2));
      if (interval > 0 && std::sqrt(s2) > rest_speed_ * interval)
        P.col(last_fast_)[i] = sim.time - t0_;
      ++n;
    }
    // Over the ranks (identity serially).
    max_over_ranks(*sim.ranks, umax, vmax);
    sum_over_ranks(*sim.ranks, usum, n);
    t_prev_ = sim.time;
    time_.push_back(sim.time - t0_);
    max_u_.push_back(umax);
    mean_u_.push_back(n ? usum / double(n) : 0.0);
    speed_.push_back(interval > 0 ? vmax / interval : 0.0);
  }

  std::map<std::string, double> metrics(Simulation<D>& sim) override {
    if (time_.empty() || time_.back() < sim.time - t0_) {
      clock_.restart();  // the state measured is always sampled
      sample(sim);
    }
    const double nan = std::nan("");
    const Particles<D>& P = sim.particles_of_body(body_);
    const auto column = columns(sim, P);
    double depth = 0, base = std::numeric_limits<double>::infinity(), front = -base;
    double top_moved = -base, volume = 0, surface = -base, moving_until = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      if (!measured(P, i)) continue;
      const double y = P.col(P.position, D - 1)[i];
      if (!surface_at_.empty() && on_line(P, i)) surface = std::max(surface, y + half_[D - 1]);
      if (displacement(P, i) <= moved_) continue;
      const double y0 = P.col(x_ref_, D - 1)[i];
      depth = std::max(depth, column[column_of(P, i)] - (y0 - half_[D - 1]));
      base = std::min(base, y0 - half_[D - 1]);
      front = std::max(front, P.col(P.position, 0)[i] + half_[0]);
      top_moved = std::max(top_moved, y + half_[D - 1]);
      volume += P.col(P.volume)[i];
      moving_until = std::max(moving_until, P.col(last_fast_)[i]);
    }
    // Over the ranks: the failed mass's extremes (the lowest base as the largest -base) and
    // volume.
    double lowest = -base;
    max_over_ranks(*sim.ranks, depth, front, top_moved, surface, moving_until, lowest);
    base = -lowest;
    sum_over_ranks(*sim.ranks, volume);
    const bool failed = volume > 0;
    std::map<std::string, double> m;
    m["failed_volume"] = volume;  // m^3, per metre of thickness in 2D (m^2)
    m["failure_depth"] = failed ? depth : 0.0;
    m["slip_base_height"] = failed ? base - bottom_ : nan;
    m["runout"] = failed ? front - toe_ : nan;
    m["moved_mass_top_height"] = failed ? top_moved - bottom_ : nan;
    m["max_displacement"] = max_u_.back();
    if (!surface_at_.empty())
      m["deposit_top_height"] = std::isfinite(surface) ? surface - bottom_ : nan;
    if (params_.has("paper_deposit_top_height"))
      m["paper_deposit_top_height"] = params_.real("paper_deposit_top_height");
    // At rest after the failed mass's last interval faster than rest_speed; still moving if
    // that is the last interval.
    m["time_to_rest"] = !failed ? 0.0 : moving_until >= time_.back() ? nan : moving_until;
    m["final_interval_speed"] = speed_.back();
    if (params_.has("paper_time_to_rest"))
      m["paper_time_to_rest"] = params_.real("paper_time_to_rest");
    double t90 = nan;
    for (size_t k = 0; k < mean_u_.size() && std::isnan(t90); ++k)
      if (mean_u_[k] >= 0.9 * mean_u_.back()) t90 = time_[k];
    m["time_to_90_percent"] = t90;
    return m;
  }

  std::vector<std::pair<std::string, std::vector<double>>> series() const override {
    return {{"time_since_reset", time_},
            {"max_displacement", max_u_},
            {"mean_displacement", mean_u_},
            {"interval_speed", speed_}};
  }

  /// The sums and extremes of the samples and metrics are over the ranks; each particle's
  /// previous position and last fast sample are particle fields (they move with it).
  bool runs_on_ranks() const override { return true; }

  /// The series and the clock; the per-particle state is in the particles' fields.
  bool save_state(std::vector<double>& s) const override {
    s = {clock_.next, t0_, t_prev_, double(stage_), double(time_.size())};
    for (const auto* v : {&time_, &max_u_, &mean_u_, &speed_})
      s.insert(s.end(), v->begin(), v->end());
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    clock_.next = s.at(0);
    t0_ = s.at(1);
    t_prev_ = s.at(2);
    stage_ = int(s.at(3));
    const auto n = std::ptrdiff_t(s.at(4));
    auto it = s.begin() + 5;
    for (auto* v : {&time_, &max_u_, &mean_u_, &speed_}) {
      v->assign(it, it + n);
      it += n;
    }
  }

 private:
  /// Begin the measurement at time t0 from the displacement reference (the reset positions).
  void restart(Simulation<D>& sim, double t0) {
    Particles<D>& P = sim.particles_of_body(body_);
    for (size_t i = 0; i < P.size(); ++i) {
      if (!measured(P, i)) continue;
      P.col(last_fast_)[i] = 0;
      for (int d = 0; d < D; ++d) P.col(prev_, d)[i] = P.col(x_ref_, d)[i];
    }
    t0_ = t_prev_ = t0;
    clock_.restart();
    time_.clear(), max_u_.clear(), mean_u_.clear(), speed_.clear();
  }

  /// Whether particle i is one of the body's own (generated with it, ids [first_id, +count));
  /// a particle a source adds later is not measured.
  bool measured(const Particles<D>& P, size_t i) const {
    return P.body[i] == body_ && size_t(P.id[i]) - first_id_ < count_;
  }

  double displacement(const Particles<D>& P, size_t i) const {
    double u2 = 0;
    for (int d = 0; d < D; ++d) u2 += std::pow(P.col(P.position, d)[i] - P.col(x_ref_, d)[i], 2);
    return std::sqrt(u2);
  }

  bool on_line(const Particles<D>& P, size_t i) const {
    for (int d = 0; d < D - 1; ++d)
      if (std::fabs(P.col(P.position, d)[i] - surface_at_[size_t(d)]) > half_[size_t(d)])
        return false;
    return true;
  }

  /// The column (a particle spacing wide along each horizontal axis, counted from the grid's
  /// origin) of particle i's reference position.
  size_t column_of(const Particles<D>& P, size_t i) const {
    size_t c = 0;
    for (int d = 0; d < D - 1; ++d)
      c = c * size_t(ncol_[size_t(d)]) +
          size_t(std::clamp(
              long(std::floor((P.col(x_ref_, d)[i] - origin_[size_t(d)]) / (2 * half_[size_t(d)]))),
              0L, ncol_[size_t(d)] - 1));
    return c;
  }

  /// The ground surface of each column in the reference configuration (its highest particle
  /// domain).
  std::vector<double> columns(const Simulation<D>& sim, const Particles<D>& P) {
    size_t n = 1;
    for (int d = 0; d < D - 1; ++d) {
      origin_[size_t(d)] = sim.grid.origin[d];
      ncol_[size_t(d)] =
          long(std::ceil((sim.grid.upper(d) - origin_[size_t(d)]) / (2 * half_[size_t(d)]))) + 1;
      n *= size_t(ncol_[size_t(d)]);
    }
    std::vector<double> top(n, -std::numeric_limits<double>::infinity());
    for (size_t i = 0; i < P.size(); ++i)
      if (measured(P, i)) {
        double& t = top[column_of(P, i)];
        t = std::max(t, P.col(x_ref_, D - 1)[i] + half_[D - 1]);
      }
    sim.ranks->max(top.data(), int(top.size()));  // over the ranks
    return top;
  }

  Params params_;
  double toe_, moved_;
  std::vector<double> surface_at_;
  double rest_speed_;
  SampleClock clock_;
  int body_ = -1, x_ref_ = -1, stage_ = -1;
  int prev_ = -1, last_fast_ = -1;  // fields: the position at the last sample, the last fast one
  size_t first_id_ = 0, count_ = 0;
  double bottom_ = 0, t0_ = 0, t_prev_ = 0;
  std::array<double, D> half_{};
  std::array<double, D> origin_{};
  std::array<long, D> ncol_{};
  std::vector<double> time_, max_u_, mean_u_, speed_;
};

LOAM_REGISTER(Reference, SlopeFailure)

}  // namespace loam
