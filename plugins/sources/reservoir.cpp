// A constant-level reservoir: keeps a box full of a body's particles without prescribing their
// velocity, so the flow out of it is whatever the model gives (the head of a permeameter, water
// standing over a soil bed and seeping into it, the upstream pool of seepage under a sheet
// pile). Unlike `inflow` (a velocity inlet) it is a pressure inlet: with gravity the level of
// the box's `refill` face sets the head, within one particle spacing.
//
// When the box holds no particle of the body it is filled with the body's lattice (the lattice
// of its particles_per_cell, aligned with the grid like a generator's) at rest. Otherwise, along
// the axis of the `refill` face, the body's particles in the box are followed: when the one
// nearest that face is a spacing s or more inside the face's layer of lattice sites, a new layer
// is created one spacing behind it (repeatedly, while the gap allows), at the mean velocity of
// the body's particles in the box. The created mass is counted in the run's mass balance.
//
// A rising pool (the upstream side of a sheet pile raised slowly, as in "Numerical Modelling of
// the Internal Erosion Process in Granular Soils using the Material Point Method", seed 000):
// `level` puts the refill face inside the box at t = 0 and `level_rate` moves it outward along its
// axis at a constant speed, level(t) = level + level_rate t, until it reaches the box's own face,
// where it stays. The face layer is then the last lattice site at or inside level(t). A
// `time_function` f >= 0 of the run's time scales the speed: level(t) = level + level_rate
// int_0^t f dt (TimeFunction::integral: exact for piecewise-linear f), a level that rises in
// steps, pauses or follows a table of speeds.
#include <algorithm>
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
class Reservoir : public Source<D> {
 public:
  using Vec = std::array<double, D>;
  static constexpr const char* name = "reservoir";
  static constexpr const char* summary =
      "keeps a box full of a body's particles (a constant level: a pressure inlet, no "
      "prescribed velocity)";
  static Schema schema() {
    Schema s;
    s.text("body", "the body whose particles are created (its material, set and spacing)")
        .required();
    s.vector("min", "m", "lower corner of the box").required();
    s.vector("max", "m", "upper corner of the box").required();
    s.choice("refill", face_names(),
             "the side of the box where new layers come in: its free surface (y+ in 2D, z+ in 3D "
             "for a pool under gravity) or the far end of a supply")
        .required();
    s.real("level", "m",
           "position of the refill face along its axis at t = 0, inside the box (default: the "
           "box's face)");
    s.real("level_rate", "m/s",
           "speed at which the refill face moves outward (a rising pool), until it reaches the "
           "box's face")
        .def("0")
        .non_negative();
    s.plugin("time_function", "time_function",
             "factor f >= 0 on level_rate over the run's time (absent: 1)");
    s.check([](const Params& p, Diagnostics& d) {
      check_box_corners(p, d);
      if (p.present("time_function") && !(p.real("level_rate") > 0))
        d.error(p.where("time_function"), p.path("time_function"),
                "the time function scales level_rate: give a level_rate > 0");
    });
    return s;
  }
  explicit Reservoir(const Params& p)
      : params_(p), refill_(parse_face(p.text("refill"))), rate_(p.real("level_rate")), f_(p) {
    for (int d = 0; d < D; ++d) {
      lo_[size_t(d)] = p.vec("min")[size_t(d)];
      hi_[size_t(d)] = p.vec("max")[size_t(d)];
    }
  }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    if (!check_face(refill_, D, params_, "refill", diag)) return;
    body_ = sim.body_param(params_, "body", diag, /*need_particles=*/false);
    if (body_ < 0) return;
    const Body& body = sim.bodies[size_t(body_)];
    for (int d = 0; d < D; ++d) s_[size_t(d)] = body.spacing[size_t(d)];
    const auto& g = sim.grid;
    if (!g.holds_box(lo_, hi_)) {
      diag.error(params_.where(), params_.path(),
                 "the reservoir " + format_box(lo_, hi_) + " is outside the grid " +
                     format_box(g.origin, g.upper_corner()));
      return;
    }
    box_lattice<D>(g, lo_, hi_, s_, refill_.axis, refill_.upper, sites_, layer_);
    if (sites_.empty()) {
      diag.error(params_.where(), params_.path(),
                 "the reservoir holds no lattice site of body '" + body.name +
                     "' (thinner than its particle spacing?)");
      return;
    }
    const int a = refill_.axis;
    origin_ = g.origin[size_t(a)];
    const double face = refill_.upper ? hi_[size_t(a)] : lo_[size_t(a)];
    level0_ = params_.has("level") ? params_.real("level") : face;
    if (level0_ < lo_[size_t(a)] || level0_ > hi_[size_t(a)])
      diag.error(params_.where("level"), params_.path("level"),
                 "level " + format_number(level0_) + " is outside the box along axis " +
                     std::to_string(a) + " [" + format_number(lo_[size_t(a)]) + ", " +
                     format_number(hi_[size_t(a)]) + "]");
    else if (!reaches(face_site(0.0)))
      diag.error(params_.where("level"), params_.path("level"),
                 "no lattice site of body '" + body.name + "' lies inside level " +
                     format_number(level0_) + " (spacing " + format_number(s_[size_t(a)]) + ")");
  }

  void region(Vec& lower, Vec& upper) const override { lower = lo_, upper = hi_; }
  /// The particles in the box are followed over all ranks (the nearest one to the refill face
  /// a MAX, their count and velocity sums a sum), so every rank creates the same layers.
  bool runs_on_ranks() const override { return true; }
  bool save_state(std::vector<double>&) const override { return true; }  // none: the level is t's

  void apply(Simulation<D>& sim, double) override {
    if (body_ < 0 || layer_.empty()) return;
    const int a = refill_.axis;
    // The body's particles in the box: the one nearest the refill side, and their mean velocity.
    const Particles<D>& P = sim.particles_of_body(body_);
    double nearest = -std::numeric_limits<double>::infinity();  // sign * coordinate
    Vec v{};
    size_t count = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != body_) continue;
      bool in = true;
      for (int d = 0; d < D; ++d) {
        const double x = P.col(P.position, d)[i];
        in = in && x >= lo_[size_t(d)] && x <= hi_[size_t(d)];
      }
      if (!in) continue;
      nearest = std::max(nearest, sign() * P.col(P.position, a)[i]);
      for (int d = 0; d < D; ++d) v[size_t(d)] += P.col(P.velocity, d)[i];
      ++count;
    }
    if (sim.ranks->distributed()) {
      nearest = sim.ranks->max(nearest);
      double sums[D + 1];
      for (int d = 0; d < D; ++d) sums[d] = v[size_t(d)];
      sums[D] = double(count);
      sim.ranks->sum(sums, D + 1);
      for (int d = 0; d < D; ++d) v[size_t(d)] = sums[d];
      count = size_t(sums[D]);
    }
    const double site = sign() * face_site(sim.time), sa = s_[size_t(a)];
    if (count == 0) {  // empty: fill it up to the level
      std::vector<Vec> x;
      for (const Vec& y : sites_)
        if (sign() * y[size_t(a)] <= site + 1e-9 * sa) x.push_back(y);
      sim.add_particles(body_, x, Vec{});
      return;
    }
    for (int d = 0; d < D; ++d) v[size_t(d)] /= double(count);
    std::vector<Vec> x;
    while (site - nearest >= sa * (1 - 1e-9)) {
      nearest += sa;
      for (Vec y : layer_) {
        y[size_t(a)] = sign() * nearest;
        x.push_back(y);
      }
    }
    sim.add_particles(body_, x, v);
  }

 private:
  double sign() const { return refill_.upper ? 1.0 : -1.0; }
  /// The coordinate of the face layer at time t: the last lattice site at or inside
  /// level(t) = level + level_rate t (outward), never beyond the box's own end layer.
  double face_site(double t) const {
    const int a = refill_.axis;
    const double travel = f_.integral(0, t);
    const double sa = s_[size_t(a)], level = level0_ + sign() * rate_ * travel;
    const double k = (level - origin_) / sa - 0.5, end = layer_[0][size_t(a)];
    const double y =
        origin_ + ((refill_.upper ? std::floor(k + 1e-9) : std::ceil(k - 1e-9)) + 0.5) * sa;
    return sign() * std::min(sign() * y, sign() * end);
  }
  /// Some lattice site of the box lies at or inside the face coordinate y.
  bool reaches(double y) const {
    const int a = refill_.axis;
    for (const Vec& x : sites_)
      if (sign() * x[size_t(a)] <= sign() * y + 1e-9 * s_[size_t(a)]) return true;
    return false;
  }

  Params params_;
  Face refill_;
  Vec lo_{}, hi_{}, s_{};
  double rate_ = 0, level0_ = 0, origin_ = 0;  // origin_: the grid origin along the axis
  TimeFactor<D> f_;
  int body_ = -1;
  std::vector<Vec> sites_, layer_;  // every lattice site of the box; those of the refill layer
};

LOAM_REGISTER(Source, Reservoir)

}  // namespace loam
