// Pressure on the wall of a cavity inside a body, or of an empty region beside it: a borehole
// charge, a pressurised tunnel, a cavity expansion, a pond or tailings lagoon against a dam's face
// and its floor. The cavity is a generator region that describes its surface (sphere, cylinder,
// polygon); usually the same region the body's `difference` generator left empty, or a region the
// body's own boundary bounds. Its wall is sampled with quadrature points x_q (normal n_q, area
// A_q, about a quarter particle spacing apart, Generator::surface_samples, whose areas sum to the
// wall's exactly), and each sample's force goes to the body particle nearest to it:
//   f_p = f(t) sum_{q -> p} p(x_q) A_q n_q,   p(x) = pressure + unit_weight max(0, level - x_v),
// n_q the cavity's outward normal (away from the cavity, into the body), x_v the vertical
// coordinate (y in 2D, z in 3D): a uniform pressure plus, optionally, the hydrostatic pressure
// of a fluid standing to `level` (water, or tailings as an equivalent fluid). So the loaded area
// and the resultant are the wall's to round-off, whatever the lattice, and each wall particle is
// pushed along its own share of the wall's normal. Samples the body does not cover (beyond a
// quarter model's symmetry planes, a pond's free surface, another body's part of the wall: the
// body's region does not hold x_q + (s/2) n_q, s the particle spacing) are dropped, as are
// samples with no body particle within 2 s. Normals and areas are those of the reference
// configuration (a nominal pressure, as `traction`'s); the forces act at the particle centres.
#include <cmath>
#include <limits>
#include <map>
#include <memory>

#include "framework/load_time.hpp"
#include "framework/registry.hpp"
#include "framework/simulation.hpp"
#include "plugins/generators/surface_samples.hpp"

namespace loam {

template <int D>
class CavityPressure : public Load<D> {
 public:
  static constexpr const char* name = "cavity_pressure";
  static constexpr const char* summary =
      "pressure on a cavity's wall (borehole, tunnel) or a pond's bed and banks (uniform, "
      "hydrostatic or both): each wall particle pushed along its own outward normal";
  static Schema schema() {
    Schema s;
    s.text("body", "body around the cavity").required();
    s.plugin("cavity", "generator",
             "the cavity: a region that describes its surface (sphere, cylinder, polygon); only "
             "its wall beside the body is loaded (not a cylinder's ends, not a pond's free "
             "surface)")
        .required();
    s.real("pressure", "Pa",
           "uniform pressure in the cavity (positive pushes the wall outwards); give it, a "
           "unit_weight, or both")
        .def("0");
    s.real("unit_weight", "N/m^3",
           "hydrostatic part: unit_weight (level - x_v) where the wall lies below `level`, x_v "
           "the vertical coordinate (y in 2D, z in 3D): the pressure of a fluid filling the cavity "
           "to that level (water 9810; tailings as an equivalent fluid)")
        .def("0")
        .min(0);
    s.real("level", "m",
           "height (y in 2D, z in 3D) of the fluid surface; required with unit_weight");
    add_load_time_keys(s);
    s.check([](const Params& p, Diagnostics& d) {
      const bool fluid = p.real("unit_weight") > 0;
      if (fluid && !p.present("level"))
        d.error(p.where("unit_weight"), p.path("unit_weight"),
                "a unit_weight needs the `level` of the fluid's surface");
      if (!fluid && p.present("level"))
        d.error(p.where("level"), p.path("level"), "a `level` needs a unit_weight > 0");
      if (!fluid && p.real("pressure") == 0)
        d.error(p.where("pressure"), p.path("pressure"),
                "the load is zero: give a pressure or a unit_weight with a level");
    });
    return s;
  }
  explicit CavityPressure(const Params& p)
      : params_(p),
        cavity_(Registry::instance().create<Generator, D>(p.section("cavity"))),
        pressure_(p.real("pressure")),
        unit_weight_(p.real("unit_weight")),
        level_(p.present("level") ? p.real("level") : 0.0),
        time_(p) {}
  bool uses_particle_forces() const override { return true; }
  /// Every rank holds the whole wall's loaded ids and forces and applies those of its own
  /// particles (assign_samples).
  bool runs_on_ranks() const override { return true; }

  void setup(Simulation<D>& sim, Diagnostics& diag) override {
    const int b = sim.body_param(params_, "body", diag);
    if (b < 0) return;
    const Body& body = sim.bodies[size_t(b)];
    double s = 0;  // the body's largest particle spacing
    for (double h : body.spacing) s = std::max(s, h);
    const auto wall = cavity_wall(*cavity_, params_, "cavity", s / 4, diag);
    if (wall.empty()) return;
    if (!body.params.has("generator")) {
      diag.error(params_.where("body"), params_.path("body"),
                 "body '" + body.name + "' starts empty (no generator): it has no cavity wall");
      return;
    }
    const auto region = Registry::instance().create<Generator, D>(body.params.section("generator"));
    set_ = sim.body_set(b);
    if (const size_t inside = count_inside(sim, b); inside > 0) {
      diag.error(params_.where("cavity"), params_.path("cavity"),
                 "the cavity holds " + std::to_string(inside) + " particles of body '" + body.name +
                     "': a cavity is empty (subtract it from the body's region with a "
                     "`difference` generator)");
      return;
    }
    assign_samples(sim, b, *region, wall, s);
    if (ids_.empty())
      diag.error(params_.where("cavity"), params_.path("cavity"),
                 "no particle of body '" + body.name +
                     "' lies on the cavity's wall (within two particle spacings of it)");
  }

  void apply_to_particles(Simulation<D>& sim, double t) override {
    const double f = time_(t);
    sim.add_external_forces(set_, ids_, [&](size_t k, int d) { return f * force_[k][size_t(d)]; });
  }

 private:
  using Cell = std::array<long, D>;
  static Cell cell_of(const std::array<double, D>& x, double s) {
    Cell c{};
    for (int d = 0; d < D; ++d) c[size_t(d)] = long(std::floor(x[size_t(d)] / s));
    return c;
  }

  /// The body's particles inside the cavity, over all ranks.
  size_t count_inside(const Simulation<D>& sim, int b) const {
    const auto& P = sim.sets[size_t(set_)].particles;
    double n = 0;
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != b) continue;
      std::array<double, D> x{};
      for (int d = 0; d < D; ++d) x[size_t(d)] = P.col(P.position, d)[i];
      n += cavity_->contains(x);
    }
    sim.ranks->sum(&n, 1);
    return size_t(n);
  }

  /// Pressure at a wall sample (before the time factor).
  double pressure_at(const std::array<double, D>& x) const {
    return pressure_ + unit_weight_ * std::max(0.0, level_ - x[size_t(D - 1)]);
  }

  /// Each wall sample's force p(x_q) A_q n_q to the nearest body particle (within 2 s), found
  /// through a hash of the particles near the cavity by cells of size s. Under mpirun each rank
  /// finds its own nearest particle of every sample, the ranks' candidates are gathered, and
  /// every rank keeps the whole wall's loaded ids and forces (a particle keeps its load when
  /// it changes rank).
  void assign_samples(const Simulation<D>& sim, int b, const Generator<D>& region,
                      const std::vector<typename Generator<D>::SurfaceSample>& wall, double s) {
    const auto& P = sim.sets[size_t(set_)].particles;
    const auto lo = cavity_->lower(), hi = cavity_->upper();
    std::map<Cell, std::vector<size_t>> near;
    for (size_t i = 0; i < P.size(); ++i) {
      if (P.body[i] != b) continue;
      std::array<double, D> x{};
      bool close = true;
      for (int d = 0; d < D; ++d) {
        x[size_t(d)] = P.col(P.position, d)[i];
        close =
            close && x[size_t(d)] > lo[size_t(d)] - 3 * s && x[size_t(d)] < hi[size_t(d)] + 3 * s;
      }
      if (close) near[cell_of(x, s)].push_back(i);
    }
    std::vector<const typename Generator<D>::SurfaceSample*> samples;
    std::vector<double> mine;  // per sample: this rank's nearest particle (r2, setup_order)
    for (const auto& q : wall) {
      std::array<double, D> outside{};
      for (int d = 0; d < D; ++d)
        outside[size_t(d)] = q.x[size_t(d)] + 0.5 * s * q.normal[size_t(d)];
      if (!region.contains(outside)) continue;  // not on this body's wall
      // The nearest particle within 2 s: (r2, setup_order), smallest first.
      const Cell c = cell_of(q.x, s);
      std::array<double, 4> best{std::numeric_limits<double>::infinity(), 0, 0, 0};
      for (int k = 0; k < int(std::pow(5, D)); ++k) {  // the cells within 2 of c
        Cell n = c;
        for (int d = 0, r = k; d < D; ++d, r /= 5) n[size_t(d)] += r % 5 - 2;
        const auto it = near.find(n);
        if (it == near.end()) continue;
        for (size_t i : it->second) {
          double r2 = 0;
          for (int d = 0; d < D; ++d) {
            const double e = P.col(P.position, d)[i] - q.x[size_t(d)];
            r2 += e * e;
          }
          if (r2 > 4 * s * s) continue;
          const auto order = setup_order(P, sim.grid, i);
          const std::array<double, 4> cand{r2, order[0], order[1], order[2]};
          if (cand < best) best = cand;
        }
      }
      samples.push_back(&q);
      mine.insert(mine.end(), best.begin(), best.end());
    }
    const std::vector<double> nearest = smallest_over_ranks(*sim.ranks, mine, 4, 4);
    std::map<uint32_t, std::array<double, D>> share;  // particle id -> sum p_q A_q n_q
    for (size_t k = 0; k < samples.size(); ++k) {
      if (nearest[4 * k] == std::numeric_limits<double>::infinity()) continue;  // none within 2 s
      const auto& q = *samples[k];
      auto& a = share[uint32_t(nearest[4 * k + 3])];
      const double pa = pressure_at(q.x) * q.area;
      for (int d = 0; d < D; ++d) a[size_t(d)] += pa * q.normal[size_t(d)];
    }
    for (const auto& [id, a] : share) {
      ids_.push_back(id);
      force_.push_back(a);
    }
  }

  Params params_;
  std::unique_ptr<Generator<D>> cavity_;
  double pressure_, unit_weight_, level_;
  LoadTime<D> time_;
  int set_ = 0;
  std::vector<uint32_t> ids_;
  std::vector<std::array<double, D>> force_;  // sum p_q A_q n_q per particle, at f(t) = 1
};

LOAM_REGISTER(Load, CavityPressure)

}  // namespace loam
