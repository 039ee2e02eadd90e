#pragma once
// Harr's (1962) head field under a single sheet pile in a half-space (the piping of "Numerical
// Modelling of the Internal Erosion Process in Granular Soils using the Material Point Method",
// seed 000; docs/verification.md I), shared by the sheet_pile_seepage reference and its tests.
#include <cmath>
#include <complex>

namespace loam {

/// Harr's excess head fraction (h - h_down) / ΔH at (x, y) for a pile of depth d: x from the
/// pile (downstream positive), y from the soil surface (up positive, y < 0 in the soil).
/// h = (ΔH / π) Re[arccos(t / d)], t = ±√(z² + d²), z = x + i y: 1 on the upstream surface, 0
/// on the downstream one, 1/2 at the tip and below it, 1/6 at mid-depth of the downstream face.
inline double harr_head_fraction(double x, double y, double d) {
  const std::complex<double> z(x, y);
  std::complex<double> t = std::sqrt(z * z + d * d);  // principal branch: Re t >= 0
  if (x < 0) t = -t;  // upstream: continuous across the cut below the tip (x = 0, y < -d)
  return std::acos(t / d).real() / M_PI;
}

}  // namespace loam
