#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>

#include "control/laws/lyapunov.hpp"

using namespace exc;
using namespace exc::control;

TEST_CASE("firmware/lyapunov: P solves A^T P + P A + Q = 0, is SPD, and matches the 2x2 closed form") {
  const Vec4 kp(400, 300, 200, 100), kv(40, 35, 30, 20);
  const Vec8 q_diag = (Vec8() << 1, 2, 3, 4, 5, 6, 7, 8).finished();
  const Mat8 A = error_dynamics_matrix(kp, kv);
  const Mat8 Q = q_diag.asDiagonal();
  Mat8 P;
  REQUIRE(solve_lyapunov(A, Q, P));
  CHECK((A.transpose() * P + P * A + Q).norm() < 1e-10);
  CHECK((P - P.transpose()).norm() == 0);
  CHECK(Eigen::SelfAdjointEigenSolver<Mat8>(P).eigenvalues().minCoeff() > 0);
  // Per joint the equation decouples into 2x2 blocks; solving them by hand:
  //   -2 kp p12 + q1 = 0, p11 - kv p12 - kp p22 = 0, 2 p12 - 2 kv p22 + q2 = 0.
  for (int j = 0; j < 4; ++j) {
    const double q1 = q_diag[j], q2 = q_diag[4 + j];
    const double p12 = q1 / (2 * kp[j]);
    const double p22 = (2 * p12 + q2) / (2 * kv[j]);
    const double p11 = kv[j] * p12 + kp[j] * p22;
    CHECK(P(j, j) == doctest::Approx(p11).epsilon(1e-10));
    CHECK(P(j, 4 + j) == doctest::Approx(p12).epsilon(1e-10));
    CHECK(P(4 + j, 4 + j) == doctest::Approx(p22).epsilon(1e-10));
  }
}

TEST_CASE("firmware/lyapunov refuses an unstable error dynamics") {
  Mat8 A = error_dynamics_matrix(Vec4::Constant(100), Vec4::Constant(20));
  A(7, 7) = +5;  // a negative damping on one joint
  Mat8 P;
  CHECK(!solve_lyapunov(A, Mat8::Identity(), P));
}
