#pragma once
// Drag-law plugin interface: the interaction force between pore water and soil skeleton in
// two-phase (saturated) schemes. A drag law is chosen by name in a two-phase scheme's config and
// owned by that scheme; nothing else calls it.
//
// Convention (docs/verification.md D). The drag force on the water, per unit MIXTURE volume, is
//     f = -Q (w - v),   Q >= 0 in kg/(m^3 s) = N s/m^4,
// with w the water and v the solid (skeleton) velocity; the skeleton receives +Q (w - v).
// Q is defined so that steady seepage obeys Darcy's law for the flux q = n (w - v):
//     Q (w - v) = -n grad(p)   (excess pore pressure p)   <=>   q = -(k / gamma_w) grad(p),
// hence for Darcy Q = n^2 gamma_w / k = n^2 mu_w / kappa (k hydraulic conductivity in m/s,
// kappa intrinsic permeability in m^2, k = kappa gamma_w / mu_w, gamma_w = rho_w g).
// A scheme that writes the water momentum per unit WATER volume, as the FEM-and-MPM comparison
// of large-strain consolidation does (seed 001, eq. 11, coefficient n gamma_w / k; its copy names
// no title or authors, docs/verification.md lists it), uses Q / n there: n gamma_w / k for Darcy.
// Time step: Q relaxes w - v at a rate of about Q / (n rho_w) (plus Q / ((1 - n) rho_s) for the
// skeleton); an explicit drag update needs dt < ~2 n rho_w / Q, which low permeability makes
// tiny; an implicit (node-wise) drag update has no such limit.
//
// The Ergun law of docs/verification.md D has an extra buoyancy-like term -p_w grad(n); it depends
// on the pore pressure and the porosity gradient, which only the scheme has, so the SCHEME adds it.
// A drag plugin returns Q only.
//
// Hot path: schemes call coefficient() once per batch (per particle block, per material range or
// over all nodes) every step. Arrays are contiguous; implementations are plain loops without
// virtual calls, allocation or branches on the data (they vectorise).
#include <cstddef>

namespace loam {

template <int D>
class Simulation;
class Diagnostics;

template <int D>
class Drag {
 public:
  static constexpr const char* kind = "drag";
  virtual ~Drag() = default;

  /// Optional set-up (e.g. to request particle fields); called by the owning scheme from its own
  /// setup, after the particles exist.
  virtual void setup(Simulation<D>&, Diagnostics&) {}

  /// Drag coefficient Q[i] (kg/(m^3 s), per unit mixture volume, see above) of `count` points
  /// from their current porosity n[i] (in (0, 1); the scheme keeps it there) and relative speed
  /// speed[i] = |w - v| (m/s, >= 0). `speed` may be nullptr, meaning |w - v| = 0: the laminar
  /// limit, exact for laws that are not speed_dependent(). Q may alias neither input.
  virtual void coefficient(size_t count, const double* porosity, const double* speed,
                           double* Q) const = 0;

  /// True if Q depends on |w - v| (non-Darcy laws such as Ergun). When false, Q is linear drag:
  /// a scheme may skip computing |w - v|, and an implicit drag update is exact in one solve.
  virtual bool speed_dependent() const { return false; }

  /// Darcy hydraulic conductivity k (m/s) at porosity n, in the laminar (slow-flow) limit:
  /// k = n^2 gamma_w / Q(n, 0). For documentation, time-step estimates and the Terzaghi
  /// consolidation coefficient c_v = k M / gamma_w.
  virtual double hydraulic_conductivity(double porosity) const = 0;

  /// Water properties the law was built with (given at construction), so a scheme can use or
  /// cross-check them: density rho_w (kg/m^3) and dynamic viscosity mu_w (Pa s).
  virtual double water_density() const = 0;
  virtual double water_viscosity() const = 0;
};

}  // namespace loam
