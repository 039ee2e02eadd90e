#pragma once
// Strain measures of the output (not of the time step): the magnitude of the logarithmic strain
// of the deformation since a reference state, the `strain_magnitude` output field.
#include <Eigen/Dense>
#include <cmath>

namespace loam {

/// ||eps|| = sqrt(eps : eps) of the logarithmic (Hencky) strain eps = 1/2 ln(B), B = F F^T, of
/// the deformation F = F_now F_ref^-1 since a reference state (both row-major D x D):
/// sqrt(sum_i ln^2 lambda_i) over the principal stretches lambda_i (in 2D plane strain the
/// out-of-plane stretch is 1). For small strain it is sqrt(eps : eps) of the small-strain tensor,
/// the measure of Figure 9 (eq. 3) of the FEM-and-MPM analysis of a hypothetical Mohr-Coulomb
/// slope (seed 004; its copy names no title or authors, docs/verification.md lists it); unlike
/// that tensor, a rigid rotation gives 0.
template <int D>
double hencky_strain_norm(const double* F_now, const double* F_ref) {
  using Mat = Eigen::Matrix<double, D, D>;
  const Mat F = Eigen::Map<const Eigen::Matrix<double, D, D, Eigen::RowMajor>>(F_now) *
                Eigen::Map<const Eigen::Matrix<double, D, D, Eigen::RowMajor>>(F_ref).inverse();
  const Mat B = F * F.transpose();
  const auto b = Eigen::SelfAdjointEigenSolver<Mat>(B, Eigen::EigenvaluesOnly).eigenvalues();
  double s = 0;
  for (int i = 0; i < D; ++i) s += std::pow(std::log(b[i]), 2);
  return 0.5 * std::sqrt(s);
}

}  // namespace loam
