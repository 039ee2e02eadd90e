#pragma once
// Quadrature points on circles and spheres for Generator::surface_samples: midpoint rules whose
// point counts are multiples of 4 on every circle, so that the samples are symmetric about the
// coordinate planes through the centre and a quarter of them covers a quarter circle exactly.
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <vector>

#include "framework/diagnostics.hpp"
#include "framework/generator.hpp"
#include "framework/params.hpp"

namespace loam {

/// The wall of the cavity given under `key` of p (cavity_pressure, blast_wave), sampled about
/// `spacing` apart (Generator::surface_samples), or a located error, and empty, when the region
/// has a problem or does not describe its surface.
template <int D>
std::vector<typename Generator<D>::SurfaceSample> cavity_wall(const Generator<D>& cavity,
                                                              const Params& p,
                                                              const std::string& key,
                                                              double spacing, Diagnostics& diag) {
  if (std::string problem = cavity.check(); !problem.empty()) {
    diag.error(p.where(key), p.path(key), problem);
    return {};
  }
  auto wall = cavity.surface_samples(spacing);
  if (wall.empty())
    diag.error(p.where(key), p.path(key),
               "a '" + p.section(key).type() +
                   "' region does not describe its surface; a cavity is a sphere, a cylinder or a polygon");
  return wall;
}

/// Points on a circle of radius r about the origin in the plane (cos t, sin t): angles, and the
/// arc each stands for, with about `spacing` between neighbours.
inline std::vector<std::pair<double, double>> circle_rule(double r, double spacing) {
  const int n = 4 * std::max(2, int(std::ceil(2 * M_PI * r / (4 * spacing))));
  std::vector<std::pair<double, double>> rule;
  for (int k = 0; k < n; ++k) rule.emplace_back((k + 0.5) * 2 * M_PI / n, 2 * M_PI * r / n);
  return rule;
}

/// Midpoint sampling of a sphere (3D) of radius r about the origin: latitude bands about z with
/// circle_rule points on each, each point's area r^2 (cos t0 - cos t1) 2 pi / n exactly.
struct SpherePoint {
  std::array<double, 3> normal;
  double area;
};
inline std::vector<SpherePoint> sphere_rule(double r, double spacing) {
  const int bands = 2 * std::max(2, int(std::ceil(M_PI * r / (2 * spacing))));
  std::vector<SpherePoint> rule;
  for (int j = 0; j < bands; ++j) {
    const double t0 = j * M_PI / bands, t1 = (j + 1) * M_PI / bands, t = 0.5 * (t0 + t1);
    const double band = r * r * (std::cos(t0) - std::cos(t1)) * 2 * M_PI;
    const auto ring = circle_rule(r * std::sin(t), spacing);
    for (const auto& [phi, arc] : ring)
      rule.push_back({{std::sin(t) * std::cos(phi), std::sin(t) * std::sin(phi), std::cos(t)},
                      band / double(ring.size())});
  }
  return rule;
}

}  // namespace loam
