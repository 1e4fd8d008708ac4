#include "control/laws/lyapunov.hpp"

#include <Eigen/Dense>

namespace exc::control {
namespace {

// Column-major vec: vec(A^T P) = (I (x) A^T) vec(P), vec(P A) = (A^T (x) I) vec(P).
bool solve_kronecker(const Eigen::MatrixXd& A, const Eigen::MatrixXd& Q, Eigen::MatrixXd& P) {
  const Eigen::Index n = A.rows();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n * n, n * n);
  const Eigen::MatrixXd At = A.transpose();
  for (Eigen::Index b = 0; b < n; ++b) K.block(b * n, b * n, n, n) += At;  // I (x) A^T
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c) K.block(r * n, c * n, n, n).diagonal().array() += At(r, c);  // A^T (x) I
  const Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(Q.data(), n * n);
  const Eigen::VectorXd p = K.partialPivLu().solve(-q);
  P = Eigen::Map<const Eigen::MatrixXd>(p.data(), n, n);
  P = 0.5 * (P + P.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(P);
  return eig.eigenvalues().minCoeff() > 0 && ((At * P + P * A + Q).norm() <= 1e-9 * (Q.norm() + 1));
}

// The laws' error dynamics couple a joint's own states only (gains are per joint): states j, j + 4
// (and j + 8) form a group of G = n / 4, and with Q coupling no two groups either P has the same
// blocks. Each group's G x G equation is then a (G^2 x G^2) Kronecker system of fixed size, so the
// solve needs a few hundred bytes instead of the full (n^2 x n^2) system's 32 KB (n = 8) to 165 KB
// (n = 12) of heap: the Cortex-M7 image's RAM (docs/target.md). Any other A or Q takes the full solve.
template <int G, typename Mat>
bool solve_per_joint(const Mat& A, const Mat& Q, Mat& P) {
  constexpr int n = 4 * G;
  const auto group = [](int i) { return i % 4; };
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c)
      if (group(r) != group(c) && (A(r, c) != 0 || Q(r, c) != 0)) return false;
  P.setZero();
  for (int j = 0; j < 4; ++j) {
    Eigen::Matrix<double, G, G> a, q;
    for (int r = 0; r < G; ++r)
      for (int c = 0; c < G; ++c) {
        a(r, c) = A(j + 4 * r, j + 4 * c);
        q(r, c) = Q(j + 4 * r, j + 4 * c);
      }
    Eigen::Matrix<double, G * G, G * G> K = Eigen::Matrix<double, G * G, G * G>::Zero();
    const Eigen::Matrix<double, G, G> at = a.transpose();
    for (int b = 0; b < G; ++b) K.template block<G, G>(b * G, b * G) += at;  // I (x) A^T
    for (int r = 0; r < G; ++r)
      for (int c = 0; c < G; ++c) K.template block<G, G>(r * G, c * G).diagonal().array() += at(r, c);  // A^T (x) I
    const Eigen::Matrix<double, G * G, 1> v = Eigen::Map<const Eigen::Matrix<double, G * G, 1>>(q.data());
    const Eigen::Matrix<double, G * G, 1> x = K.partialPivLu().solve(-v);
    const Eigen::Matrix<double, G, G> p = Eigen::Map<const Eigen::Matrix<double, G, G>>(x.data());
    for (int r = 0; r < G; ++r)
      for (int c = 0; c < G; ++c) P(j + 4 * r, j + 4 * c) = 0.5 * (p(r, c) + p(c, r));
  }
  return true;
}

template <int G, typename Mat>
bool solve_fixed(const Mat& A, const Mat& Q, Mat& P) {
  if (solve_per_joint<G>(A, Q, P)) {
    // The same checks as the full solve: positive definite, the equation met.
    const Eigen::SelfAdjointEigenSolver<Mat> eig(P);
    return eig.eigenvalues().minCoeff() > 0 && ((A.transpose() * P + P * A + Q).norm() <= 1e-9 * (Q.norm() + 1));
  }
  Eigen::MatrixXd p;
  const bool ok = solve_kronecker(A, Q, p);
  P = p;
  return ok;
}

}  // namespace

Mat8 error_dynamics_matrix(const Vec4& kp, const Vec4& kv) {
  Mat8 A = Mat8::Zero();
  A.topRightCorner<4, 4>().setIdentity();
  A.bottomLeftCorner<4, 4>() = (-kp).asDiagonal();
  A.bottomRightCorner<4, 4>() = (-kv).asDiagonal();
  return A;
}

Mat12 integral_error_dynamics_matrix(const Vec4& kp, const Vec4& kv, const Vec4& ki) {
  Mat12 A = Mat12::Zero();
  A.block<4, 4>(0, 4).setIdentity();
  A.block<4, 4>(4, 8).setIdentity();
  A.block<4, 4>(8, 0) = (-ki).asDiagonal();
  A.block<4, 4>(8, 4) = (-kp).asDiagonal();
  A.block<4, 4>(8, 8) = (-kv).asDiagonal();
  return A;
}

bool solve_lyapunov(const Mat8& A, const Mat8& Q, Mat8& P) { return solve_fixed<2>(A, Q, P); }
bool solve_lyapunov(const Mat12& A, const Mat12& Q, Mat12& P) { return solve_fixed<3>(A, Q, P); }

}  // namespace exc::control
