// Inflow of a body's particles through a region at a prescribed velocity: a jet inlet (seed 003:
// Liang, Zhao and Martinelli, "MPM simulations of the interaction between water jet and soil
// bed": a 2 m square inlet 5 m above the bed, 17-27 m/s), a constant inflow.
//
// The region is a box, or the patch of a grid face one particle spacing deep (`face:`). During
// the time window [start, end] it stays filled with the body's particle lattice (the lattice of
// its particles_per_cell, aligned with the grid like a generator's) moving at the prescribed
// velocity v: the region is filled when the window opens; then, along the inflow axis a (the
// axis of the largest |v_d|), the layers advance by v_a dt per step and a new layer is created
// at the upstream side each time they have advanced one spacing s_a, exactly one spacing behind
// the last one. The created mass rate is therefore rho v_a A (A the region's cross-section
// normal to a). Particles of the body inside the region are given the velocity v each step, so
// the inlet is a velocity inlet whatever the pressure downstream. A `time_function` f (of the
// time since `start`, f >= 0) scales the velocity, v f(t); the layers then advance by
// v_a times its integral (TimeFunction::integral, exact for piecewise-linear f), so a jet can
// speed up, pulse or follow a table of velocities.
#include <cmath>
#include <limits>
#include <memory>

#include "framework/boundary.hpp"
#include "framework/load_time.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "plugins/sources/box_lattice.hpp"

namespace loam {

template <int D>
class Inflow : public Source<D> {
 public:
  using Vec = std::array<double, D>;
  static constexpr const char* name = "inflow";
  static constexpr const char* summary =
      "keeps a box or a grid-face patch filled with a body's particles moving at a velocity";
  static Schema schema() {
    Schema s;
    s.text("body", "the body whose particles are created (its material, set and spacing)")
        .required();
    s.vector("min", "m",
             "lower corner of the region (with face: only the patch's extent along the face)")
        .required();
    s.vector("max", "m",
             "upper corner of the region (with face: only the patch's extent along the face)")
        .required();
    s.choice("face", face_names(),
             "make the region the patch [min, max] of this grid face, one particle spacing deep");
    s.vector("velocity", "m/s", "velocity of the inflowing particles (must not be zero)")
        .required();
    s.real("start", "s", "time the inflow starts").def("0").min(0);
    s.real("end", "s", "time the inflow stops (default: never)").positive();
    s.plugin("time_function", "time_function",
             "factor f >= 0 on the velocity over the time since start (absent: 1)");
    s.check([](const Params& p, Diagnostics& d) {
      double v2 = 0;
      for (double v : p.vec("velocity")) v2 += v * v;
      if (!(v2 > 0)) d.error(p.where("velocity"), p.path("velocity"), "zero velocity: no inflow");
      if (p.has("end") && p.real("end") <= p.real("start"))
        d.error(p.where("end"), p.path("end"), "end must be after start");
      check_box_corners(p, d, p.has("face") ? parse_face(p.text("face")).axis : -1);
    });
    return s;
  }
  explicit Inflow(const Params& p)
      : params_(p),
        start_(p.real("start")),
        end_(p.has("end") ? p.real("end") : std::numeric_limits<double>::infinity()),
        f_(p, start_) {
    for (int d = 0; d < D; ++d) {
      lo_[size_t(d)] = p.vec("min")[size_t(d)];
      hi_[size_t(d)] = p.vec("max")[size_t(d)];
      v_[size_t(d)] = p.vec("velocity")[size_t(d)];
      if (std::fabs(v_[size_t(d)]) > std::fabs(v_[size_t(axis_)])) axis_ = d;
    }
  }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    body_ = sim.body_param(params_, "body", diag, /*need_particles=*/false);
    if (body_ < 0) return;
    const Body& body = sim.bodies[size_t(body_)];
    for (int d = 0; d < D; ++d) s_[size_t(d)] = body.spacing[size_t(d)];
    if (params_.has("face") && !face_region(sim, diag)) return;
    const auto& g = sim.grid;
    if (!g.holds_box(lo_, hi_)) {
      diag.error(params_.where(), params_.path(),
                 "the source region " + format_box(lo_, hi_) + " is outside the grid " +
                     format_box(g.origin, g.upper_corner()));
      return;
    }
    lattice(sim);
    if (sites_.empty())
      diag.error(params_.where(), params_.path(),
                 "the source region holds no lattice site of body '" + body.name +
                     "' (thinner than its particle spacing " + format_number(s_[size_t(axis_)]) +
                     " m?)");
  }

  void region(Vec& lower, Vec& upper) const override { lower = lo_, upper = hi_; }
  /// What it creates follows from its state and the time alone, the same on every rank; the
  /// inlet velocity is prescribed per particle.
  bool runs_on_ranks() const override { return true; }
  bool save_state(std::vector<double>& s) const override {
    s = {filled_ ? 1.0 : 0.0, newest_time_, newest_offset_};
    return true;
  }
  void restore_state(const std::vector<double>& s) override {
    filled_ = s.at(0) != 0, newest_time_ = s.at(1), newest_offset_ = s.at(2);
  }

  void apply(Simulation<D>& sim, double t) override {
    if (body_ < 0 || t < start_ * (1 - 1e-12) || t >= end_) return;
    const Vec v = velocity(t);
    prescribe_velocity(sim, v);
    const double va = std::fabs(v_[size_t(axis_)]), sa = s_[size_t(axis_)];
    if (!filled_) {  // the window opens: fill the region
      filled_ = true;
      sim.add_particles(body_, sites_, v);
      newest_time_ = t, newest_offset_ = 0;
      return;
    }
    // The newest layer has moved newest_offset_ + v_a int f dt since newest_time_ from its site
    // by now: one more layer per spacing, exactly one spacing behind the one before.
    double a = newest_offset_ + va * f_.integral(newest_time_, t);
    std::vector<Vec> x;
    while (a >= sa * (1 - 1e-9)) {
      a = std::max(a - sa, 0.0);
      for (const Vec& site : upstream_) x.push_back(add(site, a / va));
      newest_time_ = t, newest_offset_ = a;
    }
    sim.add_particles(body_, x, v);
  }

 private:
  Params params_;
  double start_, end_;
  TimeFactor<D> f_;  // its clock starts at start_
  Vec lo_{}, hi_{}, v_{}, s_{};
  int axis_ = 0, body_ = -1;
  bool filled_ = false;
  // The newest layer: when it was created and how far from its site (along the axis, m).
  double newest_time_ = 0, newest_offset_ = 0;
  std::vector<Vec> sites_, upstream_;  // every lattice site; those of the upstream layer

  /// The patch of the face, one spacing deep; the velocity must point into the grid.
  bool face_region(const Simulation<D>& sim, Diagnostics& diag) {
    const Face f = parse_face(params_.text("face"));
    if (!check_face(f, D, params_, "face", diag)) return false;
    const double inward = f.upper ? -v_[size_t(f.axis)] : v_[size_t(f.axis)];
    if (!(inward > 0)) {
      diag.error(params_.where("velocity"), params_.path("velocity"),
                 "the velocity does not point into the grid through face " + params_.text("face") +
                     ": no inflow");
      return false;
    }
    const auto& g = sim.grid;
    const double plane = f.upper ? g.upper(f.axis) : g.origin[size_t(f.axis)];
    const double depth = s_[size_t(f.axis)];
    lo_[size_t(f.axis)] = f.upper ? plane - depth : plane;
    hi_[size_t(f.axis)] = f.upper ? plane : plane + depth;
    return true;
  }

  /// Lattice sites inside the region, and the upstream layer (box_lattice.hpp).
  void lattice(const Simulation<D>& sim) {
    box_lattice<D>(sim.grid, lo_, hi_, s_, axis_, v_[size_t(axis_)] < 0, sites_, upstream_);
  }

  /// v f(t - start).
  Vec velocity(double t) const {
    Vec v = v_;
    for (auto& c : v) c *= f_.value(t);
    return v;
  }

  /// The body's particles inside the region move at v (a velocity inlet).
  void prescribe_velocity(Simulation<D>& sim, const Vec& v) const {
    Particles<D>& P = sim.particles_of_body(body_);
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_) continue;
      bool in = true;
      for (int d = 0; d < D; ++d) {
        const double x = P.col(P.position, d)[i];
        in = in && x >= lo_[size_t(d)] && x <= hi_[size_t(d)];
      }
      if (in)
        for (int d = 0; d < D; ++d) P.col(P.velocity, d)[i] = v[size_t(d)];
    }
  }

  Vec add(const Vec& x, double lag) const {
    Vec y = x;
    for (int d = 0; d < D; ++d) y[size_t(d)] += v_[size_t(d)] * lag;
    return y;
  }
};

LOAM_REGISTER(Source, Inflow)

}  // namespace loam
