#include "control/lyapunov.hpp"

#include <Eigen/Dense>

namespace exc::control {

Mat8 error_dynamics_matrix(const Vec4& kp, const Vec4& kv) {
  Mat8 A = Mat8::Zero();
  A.topRightCorner<4, 4>().setIdentity();
  A.bottomLeftCorner<4, 4>() = (-kp).asDiagonal();
  A.bottomRightCorner<4, 4>() = (-kv).asDiagonal();
  return A;
}

bool solve_lyapunov(const Mat8& A, const Mat8& Q, Mat8& P) {
  // Column-major vec: vec(A^T P) = (I (x) A^T) vec(P), vec(P A) = (A^T (x) I) vec(P).
  constexpr int n = 8;
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(n * n, n * n);
  const Mat8 At = A.transpose();
  for (int b = 0; b < n; ++b) K.block(b * n, b * n, n, n) += At;          // I (x) A^T
  for (int r = 0; r < n; ++r)
    for (int c = 0; c < n; ++c) K.block(r * n, c * n, n, n).diagonal().array() += At(r, c);  // A^T (x) I
  Eigen::VectorXd q = Eigen::Map<const Eigen::VectorXd>(Q.data(), n * n);
  const Eigen::VectorXd p = K.partialPivLu().solve(-q);
  P = Eigen::Map<const Mat8>(p.data());
  P = 0.5 * (P + P.transpose()).eval();
  const Eigen::SelfAdjointEigenSolver<Mat8> eig(P);
  return eig.eigenvalues().minCoeff() > 0 && ((At * P + P * A + Q).norm() <= 1e-9 * (Q.norm() + 1));
}

}  // namespace exc::control
