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

  /// The q nearest q_free in the metric M with rows q = values (Gauss's principle of least
  /// constraint: the constrained motion departs least, in kinetic energy, from the free one;
  /// least squares where the rows conflict; rows that repeat each other count once): the component
  /// of q_free in the rows' null space, weighted by M, plus the minimum-norm solution of the rows.
  /// `impulse` gets each row's share x_i of the impulse M (q - q_free) = sum_i x_i row_i (the
  /// minimum-norm shares, so that redundant rows, the nodes of one flat face, carry it evenly).
  static Vector constrained(const Vector& q_free, const Matrix& M, const Eigen::MatrixXd& rows,
                            const Eigen::VectorXd& values, Eigen::VectorXd& impulse) {
    impulse.setZero(rows.rows());
    if (rows.rows() == 0) return q_free;
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(rows, Eigen::ComputeThinU | Eigen::ComputeFullV);
    svd.setThreshold(1e-10);
    const int rank = int(svd.rank());
    Vector q = svd.solve(values);
    if (rank < Q) {
      const Eigen::MatrixXd null = svd.matrixV().rightCols(Q - rank);
      const Eigen::MatrixXd metric = null.transpose() * M * null;
      q += null * metric.ldlt().solve(null.transpose() * M * (q_free - q));
    }
    const Eigen::VectorXd along =
        svd.matrixV().leftCols(rank).transpose() * (M * (q - q_free)).eval();
    impulse = svd.matrixU().leftCols(rank) * along.cwiseQuotient(svd.singularValues().head(rank));
    return q;
  }
};

/// What a condition that makes a body rigid tells the contact fields.
template <int D>
class RigidMotion {
 public:
  using Dofs = RigidDofs<D>;
  virtual ~RigidMotion() = default;
  /// The body (index in Simulation::bodies) that moves rigidly.
  virtual int rigid_body() const = 0;
  /// The components of q = (V, omega) prescribed at the loads' time t (bit k: component k) and
  /// their values in `value`.
  virtual unsigned prescribed(double t, typename Dofs::Vector& value) const = 0;
};

}  // namespace loam
