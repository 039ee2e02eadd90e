#pragma once
// A rigid body in contact (docs/contact.md): a body on a velocity field of its own that moves as
// one piece, q = (V, omega), V the velocity of its centre of mass x_c and omega its angular
// velocity (none in 1D, one component in 2D, three in 3D); a point x of it moves at
//   u(x) = V + omega x (x - x_c) = G(x - x_c) q.
// Its nodal momenta p_I (mass m_I) give q by the momentum and angular momentum they carry,
//   M_q q = sum_I G(x_I - x_c)^T p_I,   M_q = diag(M, J),
// with M and J the mass and inertia of its particles (point masses): for a shape function with
// linear completeness sum_I N_I(x_p) x_I = x_p, so the grid carries exactly the particles'
// momentum and angular momentum, and the internal forces add none (sum_I grad N_I = 0 and a
// symmetric stress has no moment). Constraints (a prescribed component, a component a boundary
// condition holds at a node the body reaches) are rows a q = b; the body takes the motion
// nearest q in the kinetic-energy metric that meets them (least squares where they conflict).
#include <Eigen/Dense>
#include <array>

namespace loam {

template <int D>
struct RigidDofs {
  static constexpr int R = D * (D - 1) / 2;  // rotational components
  static constexpr int Q = D + R;            // components of q = (V, omega)
  using Vector = Eigen::Matrix<double, Q, 1>;
  using Matrix = Eigen::Matrix<double, Q, Q>;
  using Map = Eigen::Matrix<double, D, Q>;  // G(r): u = G(r) q

  /// G(r) with u = V + omega x r: [I | -[r]x] (2D: omega x r = (-omega r_y, omega r_x)).
  static Map velocity_map(const double (&r)[D]) {
    Map g = Map::Zero();
    for (int d = 0; d < D; ++d) g(d, d) = 1;
    if constexpr (D == 2) {
      g(0, 2) = -r[1];
      g(1, 2) = r[0];
    } else if constexpr (D == 3) {
      g(0, 4) = r[2], g(0, 5) = -r[1];
      g(1, 3) = -r[2], g(1, 5) = r[0];
      g(2, 3) = r[1], g(2, 4) = -r[0];
    }
    return g;
  }

  /// M^{-1} b (M symmetric positive definite; 1D: one division).
  static Vector solve(const Matrix& M, const Vector& b) {
    if constexpr (Q == 1)
      return b / M(0, 0);
    else
      return M.ldlt().solve(b);
  }
};

/// Rows a_i q = b_i on q (a rigid body's constraints in a step, framework/rigid_fields.hpp),
/// decomposed once for every projection of the step.
template <int D>
class RigidRows {
 public:
  using Dofs = RigidDofs<D>;
  using Vector = typename Dofs::Vector;
  using Matrix = typename Dofs::Matrix;

  void set(const Eigen::MatrixXd& rows, const Eigen::VectorXd& values) {
    count_ = rows.rows();
    if (count_ == 0) return;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(rows, Eigen::ComputeThinU | Eigen::ComputeFullV);
    svd.setThreshold(1e-10);
    rank_ = int(svd.rank());
    particular_ = svd.solve(values);
    u_ = svd.matrixU().leftCols(rank_);
    v_ = svd.matrixV();
    sigma_ = svd.singularValues().head(rank_);
  }

  /// The q nearest q_free in the metric M that meets the rows (Gauss's principle of least
  /// constraint: the constrained motion departs least, in kinetic energy, from the free one;
  /// least squares where the rows conflict; rows that repeat each other count once): the
  /// component of q_free in the rows' null space, weighted by M, plus the minimum-norm solution
  /// of the rows. `impulse` gets each row's share x_i of the impulse M (q - q_free) = sum_i x_i
  /// row_i (the minimum-norm shares, so that redundant rows, the nodes of one flat face, carry
  /// it evenly).
  Vector constrained(const Vector& q_free, const Matrix& M, Eigen::VectorXd& impulse) const {
    impulse.setZero(count_);
    if (count_ == 0) return q_free;
    Vector q = particular_;
    if (rank_ < Dofs::Q) {
      const Eigen::MatrixXd null = v_.rightCols(Dofs::Q - rank_);
      const Eigen::MatrixXd metric = null.transpose() * M * null;
      q += null * metric.ldlt().solve(null.transpose() * M * (q_free - q));
    }
    const Eigen::VectorXd along = v_.leftCols(rank_).transpose() * (M * (q - q_free)).eval();
    impulse = u_ * along.cwiseQuotient(sigma_);
    return q;
  }

 private:
  long count_ = 0;
  int rank_ = 0;
  Vector particular_ = Vector::Zero();  // the rows' minimum-norm solution
  Eigen::MatrixXd u_, v_;               // the rows' U (rank columns) and V (all)
  Eigen::VectorXd sigma_;               // their singular values above the threshold
};

/// What a condition that makes a body rigid tells the contact fields.
template <int D>
class RigidMotion {
 public:
  using Dofs = RigidDofs<D>;
  virtual ~RigidMotion() = default;
  /// The body (index in Simulation::bodies) that moves rigidly.
  virtual int rigid_body() const = 0;
  /// The components of q = (V, omega) prescribed over the step [t, t + dt] of the loads' time
  /// (bit k: component k) and their values in `value`.
  virtual unsigned prescribed(double t, double dt, typename Dofs::Vector& value) const = 0;
};

}  // namespace loam
