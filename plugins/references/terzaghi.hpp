#pragma once
// Terzaghi one-dimensional consolidation, one-way drainage (docs/verification.md C): a layer of
// height H, drained at the top (p = 0), impermeable at the bottom (dp/dz = 0), uniform initial
// excess pore pressure p0. With zeta = z'/H (z' measured down from the drained top, 0 <= zeta <= 1)
// and the time factor T = c_v t / H^2:
//     p/p0 = sum_{m>=0} (2/M) sin(M zeta) exp(-M^2 T),      M = (2m+1) pi/2      (Fourier)
//     U    = 1 - sum_{m>=0} (2/M^2) exp(-M^2 T)             (degree of consolidation)
// The Fourier series converges slowly for small T (~180 terms at T = 1e-4, ~1.5e4 at 1e-8) and
// not at all at T = 0, so for T < kTerzaghiSwitch the functions use the equivalent image
// (short-time) series of the layer mirrored about its impermeable base, with s = 1/(2 sqrt T):
//     p/p0 = 1 - sum_{k>=0} (-1)^k [erfc((2k + zeta) s) + erfc((2k + 2 - zeta) s)]
//     U    = 2 sqrt(T) [1/sqrt(pi) + 2 sum_{k>=1} (-1)^k ierfc(k/sqrt T)]
//     ierfc(x) = exp(-x^2)/sqrt(pi) - x erfc(x)
// which needs 1-3 terms there and gives U = 2 sqrt(T/pi) up to exponentially small terms.
// Truncation: Fourier terms are bounded by b_m = (2/M_m) exp(-M_m^2 T) (U: 2/M_m^2 exp(...)),
// and b_{j+1}/b_j <= r_m = exp(-pi^2 (2m+2) T) for j >= m, so the tail after term m is at most
// b_m/(1 - r_m): the sum stops once that bound is below kTerzaghiTolerance (1e-16). The image
// series alternate with decreasing terms: they stop once a term is below the tolerance. Both
// forms are exposed for tests; they agree to ~1e-15 where both converge.
#include <cmath>

namespace loam {

constexpr double kTerzaghiTolerance = 1e-16;
constexpr double kTerzaghiSwitch = 0.01;  // below: image series; from here on: Fourier

/// p/p0 by the Fourier series (T > 0; NaN for T <= 0). `terms` receives the terms summed.
inline double terzaghi_pressure_fourier(double zeta, double T, int* terms = nullptr) {
  if (!(T > 0)) return std::nan("");
  double sum = 0;
  int m = 0;
  for (; m < 100000000; ++m) {
    const double M = (2 * m + 1) * M_PI / 2;
    const double b = 2 / M * std::exp(-M * M * T);
    sum += b * std::sin(M * zeta);
    const double r = std::exp(-M_PI * M_PI * (2 * m + 2) * T);
    if (b < kTerzaghiTolerance * (1 - r)) break;
  }
  if (terms) *terms = m + 1;
  return sum;
}

/// Degree of consolidation U by the Fourier series (T > 0; NaN for T <= 0).
inline double terzaghi_degree_fourier(double T, int* terms = nullptr) {
  if (!(T > 0)) return std::nan("");
  double sum = 0;
  int m = 0;
  for (; m < 100000000; ++m) {
    const double M = (2 * m + 1) * M_PI / 2;
    const double b = 2 / (M * M) * std::exp(-M * M * T);
    sum += b;
    const double r = std::exp(-M_PI * M_PI * (2 * m + 2) * T);
    if (b < kTerzaghiTolerance * (1 - r)) break;
  }
  if (terms) *terms = m + 1;
  return 1 - sum;
}

/// p/p0 by the image series (T >= 0; at T = 0: 1 inside, 0 at the drained top).
inline double terzaghi_pressure_images(double zeta, double T, int* terms = nullptr) {
  if (T <= 0) {
    if (terms) *terms = 0;
    return zeta > 0 ? 1.0 : 0.0;
  }
  const double s = 1 / (2 * std::sqrt(T));
  double sum = 0, sign = 1;
  int k = 0;
  for (; k < 100000; ++k) {
    const double a = std::erfc((2 * k + zeta) * s), b = std::erfc((2 * k + 2 - zeta) * s);
    sum += sign * (a + b);
    sign = -sign;
    if (a < kTerzaghiTolerance) break;  // a >= b >= every later term
  }
  if (terms) *terms = k + 1;
  return 1 - sum;
}

/// Degree of consolidation U by the image series (T >= 0).
inline double terzaghi_degree_images(double T, int* terms = nullptr) {
  if (T <= 0) {
    if (terms) *terms = 0;
    return 0;
  }
  const double rt = std::sqrt(T);
  double sum = 1 / std::sqrt(M_PI), sign = -1;
  int k = 1;
  for (; k < 100000; ++k) {
    const double x = k / rt;
    const double ierfc = std::exp(-x * x) / std::sqrt(M_PI) - x * std::erfc(x);
    sum += 2 * sign * ierfc;
    sign = -sign;
    if (ierfc < kTerzaghiTolerance) break;
  }
  if (terms) *terms = k;
  return 2 * rt * sum;
}

/// Excess pore pressure p/p0 at zeta = z'/H in [0, 1] and time factor T >= 0.
inline double terzaghi_pressure(double zeta, double T) {
  return T < kTerzaghiSwitch ? terzaghi_pressure_images(zeta, T)
                             : terzaghi_pressure_fourier(zeta, T);
}

/// Degree of consolidation U(T) = 1 - mean(p)/p0, T >= 0.
inline double terzaghi_degree(double T) {
  return T < kTerzaghiSwitch ? terzaghi_degree_images(T) : terzaghi_degree_fourier(T);
}

}  // namespace loam
