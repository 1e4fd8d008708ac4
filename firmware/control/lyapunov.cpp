#include "control/lyapunov.hpp"

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

template <typename Mat>
bool solve_fixed(const Mat& A, const Mat& Q, Mat& P) {
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

bool solve_lyapunov(const Mat8& A, const Mat8& Q, Mat8& P) { return solve_fixed(A, Q, P); }
bool solve_lyapunov(const Mat12& A, const Mat12& Q, Mat12& P) { return solve_fixed(A, Q, P); }

}  // namespace exc::control
