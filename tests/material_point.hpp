#pragma once
// One material point for unit tests of material plugins: particle 0 of a tiny one-body
// simulation, strain-driven directly through MaterialBatch (no grid, no scheme).
#include <Eigen/Dense>
#include <catch2/catch.hpp>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "sim_helpers.hpp"

namespace loam_test {

/// A one-body config in `dim` dimensions: grid extent 1 per axis, cell size 0.25, linear shape
/// functions, a box [0.25, 0.5]^dim of `material` (a YAML map) named `body`.
inline std::string point_config(int dim, const std::string& material,
                                const std::string& body = "soil") {
  std::string ext = dim == 3 ? "[1, 1, 1]" : dim == 2 ? "[1, 1]" : "[1]";
  std::string lo = dim == 3 ? "[0.25, 0.25, 0.25]" : dim == 2 ? "[0.25, 0.25]" : "[0.25]";
  std::string hi = dim == 3 ? "[0.5, 0.5, 0.5]" : dim == 2 ? "[0.5, 0.5]" : "[0.5]";
  return "grid: {extent: " + ext +
         ", cell_size: 0.25}\nshape_function: linear\nbodies:\n"
         "  - name: " +
         body + "\n    generator: {type: box, min: " + lo + ", max: " + hi +
         "}\n    material: " + material + "\ntime: {end: 1}\n";
}

/// How MaterialPoint::step updates the particle volume before the stress update.
enum class VolumeUpdate {
  none,  // volume kept (strain-driven tests of stress-only materials)
  det,   // V *= det(I + L dt), as the schemes do
  exp,   // V *= exp(tr(L) dt), exact for any L (e.g. keeps V under a pure spin)
};

/// The first particle of a one-material simulation (point_config), driven by a velocity
/// gradient L through MaterialBatch. With the default dt = 1, L is the strain increment.
template <int D>
struct MaterialPoint {
  static constexpr int NS = loam::Particles<D>::NS;
  std::unique_ptr<loam::Simulation<D>> sim;
  std::vector<double> L = std::vector<double>(size_t(D * D) * loam::kBlock, 0.0);
  loam::MaterialBatch<D> batch;
  VolumeUpdate volume_update = VolumeUpdate::none;

  explicit MaterialPoint(const std::string& material, VolumeUpdate v = VolumeUpdate::none,
                         const std::string& body = "soil")
      : sim(make_simulation<D>(point_config(D, material, body))), volume_update(v) {
    batch.begin = 0;
    batch.count = 1;
    batch.L = L.data();
    batch.particles = &sim->sets[0].particles;
    batch.dt = 1.0;
  }

  /// Handle of a particle field; throws if no plugin requested it.
  int handle(const std::string& name) const {
    const int h = sim->sets[0].particles.find(name);
    if (h < 0) throw std::runtime_error("no particle field '" + name + "'");
    return h;
  }
  double& field(int handle, int c = 0) { return sim->sets[0].particles.col(handle, c)[0]; }
  double& field(const std::string& name, int c = 0) { return field(handle(name), c); }
  double& stress(int c) { return field(sim->sets[0].particles.stress, c); }
  double& volume() { return field(sim->sets[0].particles.volume); }
  double mass() { return field(sim->sets[0].particles.mass); }
  double rho() { return mass() / volume(); }

  /// sigma = s I (tension positive).
  void isotropic(double s) {
    for (int k = 0; k < NS; ++k) stress(k) = k < 3 ? s : 0.0;
  }

  /// One step with velocity gradient l (D x D, row-major) over batch.dt: the volume update
  /// chosen by volume_update, then the material's stress update.
  void step(const std::vector<double>& l) {
    if (volume_update != VolumeUpdate::none) {
      const double dt = batch.dt;
      double f[3][3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
      double tr = 0;
      for (int i = 0; i < D; ++i) {
        tr += l[size_t(i * D + i)];
        for (int j = 0; j < D; ++j) f[i][j] += l[size_t(i * D + j)] * dt;
      }
      const double det = f[0][0] * (f[1][1] * f[2][2] - f[1][2] * f[2][1]) -
                         f[0][1] * (f[1][0] * f[2][2] - f[1][2] * f[2][0]) +
                         f[0][2] * (f[1][0] * f[2][1] - f[1][1] * f[2][0]);
      volume() *= volume_update == VolumeUpdate::exp ? std::exp(tr * dt) : det;
    }
    for (int k = 0; k < D * D; ++k) L[size_t(k) * loam::kBlock] = l[size_t(k)];
    sim->materials[0]->update_stress(batch);
  }
  /// One step over dt (which stays the batch's dt for later steps).
  void step(const std::vector<double>& l, double dt) {
    batch.dt = dt;
    step(l);
  }

  /// Every component of every particle field of the point, in field order.
  std::vector<double> save() const { return sim->sets[0].particles.state_of(0); }
  void restore(const std::vector<double>& s) { sim->sets[0].particles.restore_state(0, s); }

  /// Mean pressure, compression positive.
  double p() { return -(stress(0) + stress(1) + stress(2)) / 3; }
  /// Von Mises equivalent stress sqrt(3 J2).
  double q() {
    double v[6] = {0, 0, 0, 0, 0, 0};  // 1D and 2D store fewer components
    for (int k = 0; k < NS; ++k) v[k] = stress(k);
    const double m = -p();
    const double j2 =
        0.5 * ((v[0] - m) * (v[0] - m) + (v[1] - m) * (v[1] - m) + (v[2] - m) * (v[2] - m)) +
        v[3] * v[3] + v[4] * v[4] + v[5] * v[5];
    return std::sqrt(3 * j2);
  }
  /// Principal stresses, ascending (tension positive).
  Eigen::Vector3d principal_stress() {
    double v[6] = {0, 0, 0, 0, 0, 0};
    for (int k = 0; k < NS; ++k) v[k] = stress(k);
    Eigen::Matrix3d m;
    m << v[0], v[3], v[5], v[3], v[1], v[4], v[5], v[4], v[2];
    return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(m).eigenvalues();
  }

  double wave_speed() {
    return sim->materials[0]->wave_speed(sim->sets[0].particles, 0, sim->sets[0].particles.size());
  }
  double strain_energy() { return sim->materials[0]->strain_energy(sim->sets[0].particles, 0, 1); }

  /// One drained increment along x: axial strain -da and equal lateral normal strains e (y and,
  /// in 3D, z; 2D is plane strain, zz fixed), e found by a secant iteration from nu da and
  /// 2 nu da so that sigma_yy = -s3 to 1e-10 s3 (REQUIREd to 1e-9 s3). Returns e. D >= 2.
  double compress_at_lateral_stress(double da, double s3, double nu) {
    const auto saved = save();
    auto run = [&](double e) {
      restore(saved);
      std::vector<double> de(size_t(D * D), 0.0);
      de[0] = -da;
      for (int k = 1; k < D; ++k) de[size_t(k * D + k)] = e;
      step(de);
      return stress(1) + s3;
    };
    double e0 = nu * da, e1 = 2 * nu * da;
    double r0 = run(e0), r1 = run(e1);
    for (int it = 0; it < 60 && std::fabs(r1) > 1e-10 * s3; ++it) {
      const double e2 = e1 - r1 * (e1 - e0) / (r1 - r0);
      e0 = e1, r0 = r1, e1 = e2, r1 = run(e1);
    }
    REQUIRE(std::fabs(r1) <= 1e-9 * s3);
    return e1;
  }
};

}  // namespace loam_test
