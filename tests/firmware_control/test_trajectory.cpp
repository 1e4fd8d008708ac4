#include <doctest/doctest.h>

#include "control/task/trajectory.hpp"

using namespace exc;
using namespace exc::control;

namespace {

JointTrajectory sample_trajectory() {
  std::vector<double> t = {0.0, 1.0, 2.5, 3.0, 5.0};
  std::vector<Vec4> q = {Vec4(0.0, 2.30, 2.60, 1.95), Vec4(0.3, 2.50, 2.40, 2.10), Vec4(-0.2, 2.20, 2.90, 1.80),
                         Vec4(0.1, 2.25, 2.80, 1.85), Vec4(0.0, 2.40, 2.50, 2.00)};
  return JointTrajectory(t, q);
}

}  // namespace

TEST_CASE("firmware/spline hits every waypoint with zero end velocities") {
  const JointTrajectory traj = sample_trajectory();
  Vec4 q, qd, qdd;
  for (std::size_t i = 0; i < traj.size(); ++i) {
    // Inside the range the segment formula is used (evaluate slightly off the knot and at it).
    const double t = traj.times()[i];
    traj.evaluate(t, q, qd, qdd);
    CHECK((q - traj.points()[i]).norm() < 1e-12);
    if (i > 0 && i + 1 < traj.size()) {
      traj.evaluate(t - 1e-9, q, qd, qdd);
      CHECK((q - traj.points()[i]).norm() < 1e-8);
    }
  }
  // Clamped ends: the velocity just inside each end tends to zero.
  traj.evaluate(1e-7, q, qd, qdd);
  CHECK(qd.norm() < 1e-5);
  traj.evaluate(5.0 - 1e-7, q, qd, qdd);
  CHECK(qd.norm() < 1e-5);
  // Holds outside.
  traj.evaluate(-1.0, q, qd, qdd);
  CHECK((q - traj.points().front()).norm() == 0);
  CHECK(qd.norm() == 0);
  traj.evaluate(9.0, q, qd, qdd);
  CHECK((q - traj.points().back()).norm() == 0);
}

TEST_CASE("firmware/spline is C2: position, velocity and acceleration continuous at every knot") {
  const JointTrajectory traj = sample_trajectory();
  const double eps = 1e-8;
  for (std::size_t i = 1; i + 1 < traj.size(); ++i) {
    const double t = traj.times()[i];
    Vec4 q0, qd0, qdd0, q1, qd1, qdd1;
    traj.evaluate(t - eps, q0, qd0, qdd0);
    traj.evaluate(t + eps, q1, qd1, qdd1);
    CHECK((q1 - q0).norm() < 1e-6);
    CHECK((qd1 - qd0).norm() < 1e-5);
    CHECK((qdd1 - qdd0).norm() < 1e-4);
    // A C1 but not C2 curve (e.g. independent cubic Hermite segments) has acceleration jumps of order
    // 0.1..1 here: the bound above would catch it.
  }
}

TEST_CASE("firmware/spline derivatives agree with central finite differences") {
  const JointTrajectory traj = sample_trajectory();
  const double h = 1e-5;
  for (double t = 0.05; t < 4.95; t += 0.173) {
    Vec4 q, qd, qdd, qp, qdp, qddp, qm, qdm, qddm;
    traj.evaluate(t, q, qd, qdd);
    traj.evaluate(t + h, qp, qdp, qddp);
    traj.evaluate(t - h, qm, qdm, qddm);
    CHECK(((qp - qm) / (2 * h) - qd).norm() < 1e-6);
    CHECK(((qdp - qdm) / (2 * h) - qdd).norm() < 1e-5);
  }
}

TEST_CASE("firmware/spline rejects non-increasing times") {
  CHECK_THROWS_AS(JointTrajectory({0.0, 1.0, 1.0}, {Vec4::Zero(), Vec4::Zero(), Vec4::Zero()}),
                  std::invalid_argument);
  CHECK_THROWS_AS(JointTrajectory({0.0}, {Vec4::Zero()}), std::invalid_argument);
}
