#pragma once
// Constitutive-model plugin interface. The framework calls update_stress once per contiguous
// batch of particles of this material (never once per particle), handing it the velocity
// gradient of the batch. Stress is Cauchy, tension positive, Voigt order xx yy zz xy yz xz.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "particles.hpp"
#include "shape_function.hpp"

namespace loam {

/// The accumulated equivalent plastic deviatoric strain, the state field the elastoplastic
/// materials share (and output under one name).
inline FieldInfo plastic_strain_eq_field() {
  return {"plastic_strain_eq",
          1,
          "-",
          "equivalent plastic deviatoric strain sqrt(2/3 e:e), accumulated",
          {}};
}

class Diagnostics;
class Params;

template <int D>
struct MaterialBatch {
  size_t begin = 0;  // first particle index
  int count = 0;     // particles in the batch (<= kBlock)
  double dt = 0;
  /// Velocity gradient L_ij = dv_i/dx_j of particle begin+p at L[(i*D + j)*kBlock + p].
  const double* L = nullptr;
  Particles<D>* particles = nullptr;
};

template <int D>
class Material {
 public:
  static constexpr const char* kind = "material";
  virtual ~Material() = default;

  /// Initial mass density (kg/m^3).
  virtual double density() const = 0;
  /// Request state fields; `index` is this material's index in particles.material.
  virtual void setup(Simulation<D>&, int /*index*/, Diagnostics&) {}
  /// Set state fields of particles [begin, end) from their current (initial) stress, e.g. the
  /// preconsolidation pressure from an OCR. Called once after set-up and whenever a driver (the
  /// element test) imposes a new initial stress.
  virtual void initialize(Particles<D>&, size_t /*begin*/, size_t /*end*/) {}
  /// Largest P-wave speed (m/s) of particles [begin, end) for the CFL time step.
  virtual double wave_speed(const Particles<D>& p, size_t begin, size_t end) const = 0;
  virtual void update_stress(const MaterialBatch<D>& batch) = 0;
  /// True for a fluid: its stress follows from its current density m/V and its rate alone (no
  /// skeleton), so a scheme may drive its density (the liquid points of two_phase_double_point).
  virtual bool is_fluid() const { return false; }
  /// Strength reduction (docs/strength_reduction.md): the same model, sharing this one's state
  /// fields, with its shear strength divided by F (c / F and tan(phi) / F, each model says
  /// what else). nullptr: the model has no strength to reduce (elastic, fluid).
  virtual std::unique_ptr<Material<D>> reduced(double /*F*/) const { return nullptr; }
  /// Stored elastic energy of particles [begin, end) (J, per unit thickness in 2D), or NaN if
  /// the model does not define one.
  virtual double strain_energy(const Particles<D>&, size_t, size_t) const {
    return std::numeric_limits<double>::quiet_NaN();
  }
};

/// P-wave speed sqrt(M / rho) of particles [begin, end) for a constrained modulus M (Pa):
/// fastest where the density m / V is lowest, i.e. in stretched particles.
template <int D>
double p_wave_speed(const Particles<D>& P, size_t begin, size_t end, double M) {
  double rho_min = std::numeric_limits<double>::infinity();
  const double* m = P.col(P.mass);
  const double* V = P.col(P.volume);
#pragma omp parallel for reduction(min : rho_min) schedule(static)
  for (size_t i = begin; i < end; ++i) rho_min = std::min(rho_min, m[i] / V[i]);
  return std::sqrt(M / std::max(rho_min, 1e-300));
}

/// Elastic energy density 1/2 sigma : C^-1 : sigma (J/m^3) of a Voigt stress (xx yy zz xy yz xz)
/// for isotropic elasticity (E, nu).
inline double isotropic_energy_density(const double (&sv)[6], double E, double nu) {
  const double tr = sv[0] + sv[1] + sv[2];
  double ss = 0;
  for (int c = 0; c < 6; ++c) ss += (c < 3 ? 1.0 : 2.0) * sv[c] * sv[c];
  return 0.5 * ((1 + nu) * ss - nu * tr * tr) / E;
}

/// Stored elastic energy of particles [begin, end) for isotropic elasticity (E, nu).
template <int D>
double isotropic_elastic_energy(const Particles<D>& P, size_t begin, size_t end, double E,
                                double nu) {
  constexpr int NS = Particles<D>::NS;
  const double* V = P.col(P.volume);
  double sum = 0;
  for (size_t i = begin; i < end; ++i) {
    double sv[6] = {0, 0, 0, 0, 0, 0};
    for (int c = 0; c < NS; ++c) sv[c] = P.col(P.stress, c)[i];
    sum += V[i] * isotropic_energy_density(sv, E, nu);
  }
  return sum;
}

}  // namespace loam
