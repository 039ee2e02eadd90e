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
#include <algorithm>
#include <cmath>
#include <limits>

#include "framework/boundary.hpp"
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
    s.check([](const Params& p, Diagnostics& d) { check_box_corners(p, d); });
    return s;
  }
  explicit Reservoir(const Params& p) : params_(p), refill_(parse_face(p.text("refill"))) {
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
    if (sites_.empty())
      diag.error(params_.where(), params_.path(),
                 "the reservoir holds no lattice site of body '" + body.name +
                     "' (thinner than its particle spacing?)");
  }

  void region(Vec& lower, Vec& upper) const override { lower = lo_, upper = hi_; }

  void apply(Simulation<D>& sim, double) override {
    if (body_ < 0 || layer_.empty()) return;
    const int a = refill_.axis;
    const double sign = refill_.upper ? 1.0 : -1.0;
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
      nearest = std::max(nearest, sign * P.col(P.position, a)[i]);
      for (int d = 0; d < D; ++d) v[size_t(d)] += P.col(P.velocity, d)[i];
      ++count;
    }
    if (count == 0) {  // empty: fill it
      sim.add_particles(body_, sites_, Vec{});
      return;
    }
    for (int d = 0; d < D; ++d) v[size_t(d)] /= double(count);
    const double site = sign * layer_[0][size_t(a)], sa = s_[size_t(a)];
    std::vector<Vec> x;
    while (site - nearest >= sa * (1 - 1e-9)) {
      nearest += sa;
      for (Vec y : layer_) {
        y[size_t(a)] = sign * nearest;
        x.push_back(y);
      }
    }
    sim.add_particles(body_, x, v);
  }

 private:
  Params params_;
  Face refill_;
  Vec lo_{}, hi_{}, s_{};
  int body_ = -1;
  std::vector<Vec> sites_, layer_;  // every lattice site of the box; those of the refill layer
};

LOAM_REGISTER(Source, Reservoir)

}  // namespace loam
