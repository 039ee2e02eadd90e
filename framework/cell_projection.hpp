#pragma once
// Pressure smoothing of the two-phase schemes: a particle field (a pore pressure, a water
// density) projected per grid cell, by weighted least squares, onto the polynomials of the
// pressure space that is stable with the shape function's velocity space, as in the mixed
// finite-element pairs (Boffi, Brezzi & Fortin 2013, Mixed Finite Element Methods and
// Applications, ch. 8):
//   CellPressure::kConstant  one value per cell, the weighted mean (Q1-P0): linear tents, and
//                            GIMP and CPDI, which integrate the tents' gradients; a cell's
//                            nodal forces then depend on its particles' mean pressure only.
//   CellPressure::kLinear    a linear function per cell, discontinuous across cells (Q2-P1disc):
//                            quadratic B-splines. Their gradients vary inside a cell, so a
//                            constant per cell is not in equilibrium with the weight of the
//                            particles where a basis function is cut by a free surface (the top
//                            node of a water column takes a force 1/8 of the top cell's
//                            pressure against a weight 1/64 of the cell's), and the water
//                            accelerated without bound. A linear pressure per cell holds every
//                            linear field, the hydrostatic one included, and still removes the
//                            particle-to-particle checkerboard that exerts no nodal force.
// Both projections are idempotent (a projected field projects onto itself) and keep the
// weighted integral sum w f of each cell. The linear fit: with y the position from the cell's
// centre in cell units, ybar and fbar the weighted means, C the weighted covariance of y and c
// that of y and f, f(y) = fbar + b . (y - ybar), (C + eps I) b = c. eps = kRegularisation
// keeps the slope finite where the particles of a cell lie on one line or at one point (C
// singular) and makes the fit a continuous function of the sums. C and c come from sums (sum w
// y y / W - ybar^2, sum w f y / W - fbar ybar), so their round-off is about 1e-16 and 1e-16
// |fbar| in absolute terms, and a direction of variance var carries it into the fitted values
// as about 1e-16 |fbar| sqrt(var) / (var + eps), at most 5e-13 |fbar| with eps = 1e-8: the sums
// of another rank count stay near round-off of the field. eps takes 1.2e-7 of the slope of
// evenly spread points (var = 1/12) per projection.
// The sums run in particle order (cell_sums.hpp): the same bits at any thread count; under
// mpirun they are completed over the ranks before the fit.
#include <omp.h>

#include <Eigen/Dense>
#include <vector>

#include "cell_sums.hpp"
#include "shape_function.hpp"

namespace loam {

template <int D>
class Simulation;

template <int D>
class CellProjection {
 public:
  /// Sums per cell: W = sum w, WF = sum w f; for kLinear also sum w y_d, sum w y_d y_e (e >= d)
  /// and sum w f y_d.
  static constexpr int kLinearSums = 2 + D + D * (D + 1) / 2 + D;
  /// The linear fit's regularisation eps (cell units squared; evenly spread points have a
  /// variance of about 1/12 along each axis).
  static constexpr double kRegularisation = 1e-8;

  /// Sum the weights and weighted values `wf(i, w, wf)` of the particles of P per cell, complete
  /// the sums over the ranks, and fit each cell's polynomial of `degree`.
  template <class WeightValue>
  void fit(Simulation<D>& sim, const Particles<D>& P, CellPressure degree, WeightValue&& wv) {
    degree_ = degree;
    if (degree == CellPressure::kConstant) {
      K_ = 2;
      sum_per_cell<2>(sim.grid, P, sim.threads, cell_, sums_,
                      [&](size_t i, double* v) { wv(i, v[0], v[1]); });
    } else {
      K_ = kLinearSums;
      sum_per_cell<kLinearSums>(sim.grid, P, sim.threads, cell_, sums_, [&](size_t i, double* v) {
        double y[D];
        local_position(sim.grid, P, i, y);
        wv(i, v[0], v[1]);
        moments(y, v[0], v[1], v);
      });
    }
    sim.complete_cells(sums_, K_);  // a cell's particles may be on two ranks before migration
    if (degree == CellPressure::kLinear) fit_linear(sim.threads);
  }

  /// The cell of particle i (from the last fit).
  size_t cell(size_t i) const { return cell_[i]; }
  /// W and WF of cell c.
  double weight(size_t c) const { return sums_[size_t(K_) * c]; }
  double weighted_value(size_t c) const { return sums_[size_t(K_) * c + 1]; }
  /// The projected field at particle i: the cell's mean WF / W, or its linear fit at the point.
  double at(const Grid<D>& g, const Particles<D>& P, size_t i) const {
    const size_t c = cell_[i];
    if (degree_ == CellPressure::kConstant) return weighted_value(c) / weight(c);
    const double* a = fit_.data() + size_t(1 + 2 * D) * c;  // fbar, ybar, b
    double y[D], f = a[0];
    local_position(g, P, i, y);
    for (int d = 0; d < D; ++d) f += a[1 + D + d] * (y[d] - a[1 + d]);
    return f;
  }

 private:
  /// Particle i's position from its cell's centre, in cell units (-1/2 .. 1/2 inside the grid).
  static void local_position(const Grid<D>& g, const Particles<D>& P, size_t i, double* y) {
    for (int d = 0; d < D; ++d) {
      const double x = P.col(P.position, d)[i];
      y[d] = (x - g.origin[size_t(d)]) * g.inv_cell[size_t(d)] - (double(g.cell_of(x, d)) + 0.5);
    }
  }

  /// v[2..]: w y_d, w y_d y_e (e >= d), w f y_d, for weight w and weighted value wf.
  static void moments(const double* y, double w, double wf, double* v) {
    int k = 2;
    for (int d = 0; d < D; ++d) v[k++] = w * y[d];
    for (int d = 0; d < D; ++d)
      for (int e = d; e < D; ++e) v[k++] = w * y[d] * y[e];
    for (int d = 0; d < D; ++d) v[k++] = wf * y[d];
  }

  /// Per cell fbar, ybar and the slope b of the weighted least-squares linear fit.
  void fit_linear(int threads) {
    const long nc = long(sums_.size()) / K_;
    fit_.assign(size_t(nc) * (1 + 2 * D), 0.0);
#pragma omp parallel for schedule(static) num_threads(threads)
    for (long c = 0; c < nc; ++c) {
      const double* s = sums_.data() + size_t(K_) * size_t(c);
      double* a = fit_.data() + size_t(1 + 2 * D) * size_t(c);
      if (!(s[0] > 0)) continue;
      const double W = s[0], fbar = s[1] / W;
      Eigen::Matrix<double, D, D> C;
      Eigen::Matrix<double, D, 1> cf, ybar;
      for (int d = 0; d < D; ++d) ybar[d] = s[2 + d] / W;
      int k = 2 + D;
      for (int d = 0; d < D; ++d)
        for (int e = d; e < D; ++e, ++k) C(d, e) = C(e, d) = s[k] / W - ybar[d] * ybar[e];
      for (int d = 0; d < D; ++d) cf[d] = s[k + d] / W - fbar * ybar[d];
      C.diagonal().array() += kRegularisation;
      const Eigen::Matrix<double, D, 1> b = C.ldlt().solve(cf);
      a[0] = fbar;
      for (int d = 0; d < D; ++d) a[1 + d] = ybar[d], a[1 + D + d] = b[d];
    }
  }

  CellPressure degree_ = CellPressure::kConstant;
  int K_ = 2;
  std::vector<size_t> cell_;  // each particle's cell
  std::vector<double> sums_;  // K_ per cell
  std::vector<double> fit_;   // per cell: fbar, ybar (D), b (D)
};

}  // namespace loam
