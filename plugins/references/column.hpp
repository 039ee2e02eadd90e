#pragma once
// The measures shared by the consolidation-column references (consolidated_height, settlement):
// a body whose initial height H0 is its extent along the last axis, its current height
// sum V_p / A0 with A0 = V0 / H0 (the column's volume over its initial cross-section, counting the
// half particle beyond the outermost centres at both faces), and the largest |pore pressure| left.
#include <algorithm>
#include <cmath>

#include "framework/simulation.hpp"

namespace loam {

template <int D>
struct Column {
  int body = -1, pore = -1;  // body index; pore_pressure field or -1 (one-phase scheme)
  double H0 = 1, V0 = 1;

  /// Select the column (`body` key of p, default the first body); false on a bad name.
  bool setup(Simulation<D>& sim, const Params& p, Diagnostics& diag) {
    body = sim.body_param(p, "body", diag);
    if (body < 0) return false;
    const Body& b = sim.bodies[size_t(body)];
    H0 = b.upper[D - 1] - b.lower[D - 1];
    V0 = sum(sim, [&](size_t i) {
      return sim.particles_of_body(body).col(sim.particles_of_body(body).volume)[i];
    });
    // The body's own set must hold the field (the double-point scheme's solid set has none).
    const auto& P = sim.particles_of_body(body);
    pore = P.find("pore_pressure");
    if (pore >= 0 && !P.has(pore)) pore = -1;
    return true;
  }
  /// Sum of value(i) over the column's particles (over the ranks: every rank calls it).
  template <class F>
  double sum(const Simulation<D>& sim, F&& value) const {
    const auto& P = sim.particles_of_body(body);
    double total = 0;
    for (size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == body) total += value(i);
    sim.ranks->sum(&total, 1);
    return total;
  }
  double height(const Simulation<D>& sim) const {
    const double* V = sim.particles_of_body(body).col(sim.particles_of_body(body).volume);
    return sum(sim, [&](size_t i) { return V[i]; }) / (V0 / H0);
  }
  /// max |p| over the column (Pa), over the ranks; only meaningful when pore >= 0.
  double max_pore_pressure(const Simulation<D>& sim) const {
    const auto& P = sim.particles_of_body(body);
    double worst = 0;
    for (size_t i = 0; i < P.size(); ++i)
      if (P.body[i] == body) worst = std::max(worst, std::fabs(P.col(pore)[i]));
    return sim.ranks->max(worst);
  }
};

}  // namespace loam
