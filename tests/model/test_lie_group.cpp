// Lie-group identities of SE(3)/se(3), checked against the 4x4 matrix definitions and finite
// differences (not against the code's own formulas).
#include <doctest/doctest.h>

#include <Eigen/LU>
#include <random>

#include "model/lie_group.hpp"

using namespace exc;

namespace {
std::mt19937 rng(7);
double u(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
Twist random_twist(double scale = 1.0) {
  Twist V;
  for (int i = 0; i < 6; ++i) V[i] = u(-scale, scale);
  return V;
}
SE3 random_pose() {
  Twist S = random_twist(1.5);
  return exp_se3(S, 1.0);
}
// Matrix exponential by its power series (independent of the closed form under test).
SE3 exp_series(const SE3& A) {
  SE3 sum = SE3::Identity(), term = SE3::Identity();
  for (int k = 1; k < 40; ++k) {
    term = (term * A / k).eval();
    sum += term;
  }
  return sum;
}
Twist vee(const SE3& m) {
  Twist V;
  V << m(2, 1), m(0, 2), m(1, 0), m(0, 3), m(1, 3), m(2, 3);
  return V;
}
}  // namespace

TEST_CASE("model/exp of a twist equals the matrix exponential series") {
  for (int trial = 0; trial < 50; ++trial) {
    const Twist S = random_twist();
    const double q = u(-3, 3);
    const SE3 closed = exp_se3(S, q);
    const SE3 series = exp_series(hat(S) * q);
    CHECK((closed - series).cwiseAbs().maxCoeff() < 1e-10);
    // A rotation: orthonormal with determinant +1.
    const Mat3 R = rotation(closed);
    CHECK((R.transpose() * R - Mat3::Identity()).norm() < 1e-12);
    CHECK(R.determinant() == doctest::Approx(1.0).epsilon(1e-12));
  }
  // Pure translation (a prismatic screw) and the zero angle.
  const Twist P = (Twist() << 0, 0, 0, 1, 0, 0).finished();
  CHECK((exp_se3(P, 2.5) - translation_se3(Vec3(2.5, 0, 0))).norm() < 1e-15);
  CHECK((exp_se3(random_twist(), 0.0) - SE3::Identity()).norm() < 1e-15);
}

TEST_CASE("model/exp is a one-parameter group and its derivative is exp [S]") {
  for (int trial = 0; trial < 20; ++trial) {
    const Twist S = random_twist();
    const double a = u(-2, 2), b = u(-2, 2);
    CHECK((exp_se3(S, a) * exp_se3(S, b) - exp_se3(S, a + b)).cwiseAbs().maxCoeff() < 1e-12);
    const double h = 1e-6;
    const SE3 fd = (exp_se3(S, a + h) - exp_se3(S, a - h)) / (2 * h);
    CHECK((fd - exp_se3(S, a) * hat(S)).cwiseAbs().maxCoeff() < 1e-7);
  }
}

TEST_CASE("model/Ad and ad agree with conjugation and the matrix commutator") {
  for (int trial = 0; trial < 50; ++trial) {
    const SE3 T = random_pose(), T2 = random_pose();
    const Twist V = random_twist(), W = random_twist();
    // [Ad_T V] = T [V] T^-1
    CHECK((hat(Ad(T) * V) - T * hat(V) * T.inverse()).cwiseAbs().maxCoeff() < 1e-12);
    // Ad is a homomorphism and Ad_{T^-1} = Ad_T^-1.
    CHECK((Ad(T * T2) - Ad(T) * Ad(T2)).cwiseAbs().maxCoeff() < 1e-11);
    CHECK((Ad(inverse(T)) * Ad(T) - Mat6::Identity()).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((inverse(T) * T - SE3::Identity()).cwiseAbs().maxCoeff() < 1e-12);
    // [ad_V W] = [V][W] - [W][V]
    CHECK((hat(ad(V) * W) - (hat(V) * hat(W) - hat(W) * hat(V))).cwiseAbs().maxCoeff() < 1e-12);
    // The vector forms used in Newton-Euler equal the matrix forms.
    CHECK((Ad_apply(T, V) - Ad(T) * V).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((Ad_inv_apply(T, V) - Ad(T).inverse() * V).cwiseAbs().maxCoeff() < 1e-11);
    CHECK((ad_apply(V, W) - ad(V) * W).cwiseAbs().maxCoeff() < 1e-12);
    CHECK((vee(hat(V)) - V).norm() == 0.0);
  }
}

TEST_CASE("model/the dual adjoints (Ad transposed, ad transposed) preserve power V . F") {
  for (int trial = 0; trial < 50; ++trial) {
    const SE3 T = random_pose();
    const Twist V = random_twist();  // a twist in the parent frame A
    const Wrench F = random_twist();  // a wrench in the child frame B
    // Power is frame independent: (Ad*_{T^-1} F) . V_A = F . (Ad_{T^-1} V_A).
    CHECK(Ad_inv_dual_apply(T, F).dot(V) == doctest::Approx(F.dot(Ad_inv_apply(T, V))).epsilon(1e-12));
    CHECK((Ad_inv_dual_apply(T, F) - Ad(T).inverse().transpose() * F).cwiseAbs().maxCoeff() < 1e-10);
    const Twist W = random_twist();
    CHECK((ad_dual_apply(W, F) - ad(W).transpose() * F).cwiseAbs().maxCoeff() < 1e-12);
    // ad*_V (J V) . V = 0: gyroscopic terms do no work.
    const Mat6 J = spatial_inertia(u(1, 100), Vec3(u(-1, 1), u(-1, 1), u(-1, 1)), Vec3(u(1, 2), u(1, 2), u(1, 2)).asDiagonal());
    CHECK(ad_dual_apply(V, J * V).dot(V) == doctest::Approx(0.0).scale(J.norm() * V.squaredNorm()));
  }
}

TEST_CASE("model/spatial inertia gives the kinetic energy of a body about its centre of mass") {
  const double m = 37.0;
  const Vec3 c(0.3, -0.2, 0.7);
  const Mat3 Ic = Vec3(2.0, 3.0, 4.0).asDiagonal();
  const Mat6 J = spatial_inertia(m, c, Ic);
  CHECK((J - J.transpose()).norm() == 0.0);
  const Twist V = random_twist();
  const Vec3 w = V.head<3>(), v = V.tail<3>();
  const Vec3 v_com = v + w.cross(c);  // velocity of the centre of mass
  const double ke = 0.5 * m * v_com.squaredNorm() + 0.5 * w.dot(Ic * w);
  CHECK(0.5 * V.dot(J * V) == doctest::Approx(ke).epsilon(1e-12));
}

TEST_CASE("model/inertia_apply equals the spatial inertia matrix times the twist") {
  for (int trial = 0; trial < 50; ++trial) {
    const double m = u(1, 100);
    const Vec3 c(u(-1, 1), u(-1, 1), u(-1, 1)), Ic(u(1, 2), u(1, 2), u(1, 2));
    const Twist V = random_twist();
    const Wrench expected = spatial_inertia(m, c, Ic.asDiagonal()) * V;
    CHECK((inertia_apply(m, c, Ic, V) - expected).cwiseAbs().maxCoeff() < 1e-12 * (1 + expected.norm()));
  }
}
