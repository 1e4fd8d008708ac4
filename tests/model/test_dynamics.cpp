// Dynamics against independent evidence: the power balance tau . qd = dE/dt with the energy computed
// from finite-differenced poses (not from the Newton-Euler code), M_a against differences of inverse
// dynamics, inverse-forward round trips, and the two forward formulations against each other.
#include <doctest/doctest.h>

#include <Eigen/Eigenvalues>

#include "model/front_kinematics.hpp"
#include "model/lie_group.hpp"
#include "model/newton_euler.hpp"
#include "model_fixture.hpp"

using namespace exc;
using exc::test::reference_model;

namespace {

Twist vee(const SE3& m) {
  Twist V;
  V << m(2, 1), m(0, 2), m(1, 0), m(0, 3), m(1, 3), m(2, 3);
  return V;
}

// Total energy (kinetic + potential) from link poses at t - d, t, t + d: body twists by finite
// differences of the poses, kinetic energy 1/2 V^T J V, potential m g z of the centre of mass.
double energy_from_poses(const Model& m, const std::array<SE3, kNumJoints>& before, const std::array<SE3, kNumJoints>& now,
                         const std::array<SE3, kNumJoints>& after, double d) {
  double E = 0;
  for (int i = 0; i < kNumJoints; ++i) {
    const SE3 Xdot = (after[i] - before[i]) / (2 * d);
    const Twist V = vee(inverse(now[i]) * Xdot);
    E += 0.5 * V.dot(m.inertia[i] * V);
    const Vec3 com_world = (now[i] * m.machine.bodies[i].com.homogeneous()).head<3>();
    E += m.machine.bodies[i].mass * m.machine.gravity * com_world.z();
  }
  return E;
}

struct TreeTrajectory {
  Vec12 a, w, p, c;
  Vec12 q(double t) const { return c + a.cwiseProduct((w * t + p).array().sin().matrix()); }
  Vec12 qd(double t) const { return a.cwiseProduct(w).cwiseProduct((w * t + p).array().cos().matrix()); }
  Vec12 qdd(double t) const { return -a.cwiseProduct(w).cwiseProduct(w).cwiseProduct((w * t + p).array().sin().matrix()); }
};

}  // namespace

TEST_CASE("model/tree Newton-Euler satisfies the power balance tau . qd = dE/dt") {
  const Model& m = reference_model();
  Workspace ws(m);
  TreeTrajectory tr;
  for (int i = 0; i < kNumJoints; ++i) {
    tr.c[i] = m.prismatic[i] ? 2.0 : 0.3 * i;
    tr.a[i] = m.prismatic[i] ? 0.3 : 0.8;
    tr.w[i] = 0.7 + 0.23 * i;
    tr.p[i] = 0.5 * i;
  }
  auto poses = [&](double t) {
    tree_kinematics(m, ws, tr.q(t), tr.qd(t));
    return ws.X_Wi;
  };
  const double d = 1e-5, h = 1e-4;
  auto energy = [&](double t) { return energy_from_poses(m, poses(t - d), poses(t), poses(t + d), d); };
  for (double t = 0.0; t < 3.0; t += 0.37) {
    const double dEdt = (energy(t + h) - energy(t - h)) / (2 * h);
    tree_kinematics(m, ws, tr.q(t), tr.qd(t));
    Vec12 tau;
    tree_inverse_dynamics(m, ws, tr.qdd(t), Vec2::Zero(), tau);
    const double power = tau.dot(tr.qd(t));
    CAPTURE(t);
    CHECK(power == doctest::Approx(dEdt).epsilon(1e-4).scale(1e3));
  }
}

TEST_CASE("model/closed-chain inverse dynamics satisfies the power balance tau_a . qd_a = dE/dt") {
  const Model& m = reference_model();
  Workspace ws(m);
  const test::SmoothTrajectory tr(m);
  auto poses = [&](double t) {
    REQUIRE(update_closed_chain(m, ws, tr.q(t), tr.qd(t)).ok());
    tree_world_poses(m, ws);
    return ws.X_Wi;
  };
  const double d = 1e-5, h = 1e-4;
  auto energy = [&](double t) { return energy_from_poses(m, poses(t - d), poses(t), poses(t + d), d); };
  double max_power = 0;
  for (double t = 0.0; t < 4.0; t += 0.29) {
    const double dEdt = (energy(t + h) - energy(t - h)) / (2 * h);
    REQUIRE(update_closed_chain(m, ws, tr.q(t), tr.qd(t)).ok());
    Vec4 tau_a;
    inverse_dynamics(m, ws, tr.qdd(t), Vec2::Zero(), tau_a);
    const double power = tau_a.dot(tr.qd(t));
    max_power = std::max(max_power, std::abs(power));
    CAPTURE(t);
    CHECK(power == doctest::Approx(dEdt).epsilon(1e-4).scale(1e3));
    // The loop reaction forces close eq. 7a on the passive joints: tau_r = tau_act + H^T F_c.
    const Vec12 residual = ws.tau_r - ws.H.transpose() * ws.F_c;
    for (int k : kPassiveJoints) CHECK(std::abs(residual[k]) < 1e-6 * ws.tau_r.cwiseAbs().maxCoeff());
  }
  CHECK(max_power > 1e4);  // the trajectory really moves the machine against gravity
}

TEST_CASE("model/M_a is symmetric positive definite and equals differences of inverse dynamics") {
  const Model& m = reference_model();
  Workspace ws(m);
  test::RandomStates rs(21);
  for (int trial = 0; trial < 100; ++trial) {
    const Vec4 q_a = rs.q_a(m), qd_a = rs.qd_a();
    REQUIRE(update_closed_chain(m, ws, q_a, qd_a).ok());
    Mat4 M_a;
    mass_matrix(m, ws, M_a);
    CHECK((M_a - M_a.transpose()).cwiseAbs().maxCoeff() <= 1e-9 * M_a.cwiseAbs().maxCoeff());
    const Eigen::SelfAdjointEigenSolver<Mat4> eig(M_a);
    CHECK(eig.eigenvalues().minCoeff() > 0.0);
    // Inverse dynamics is affine in qdd_a: tau(e_j) - tau(0) = M_a e_j.
    Vec4 tau0, tauj;
    inverse_dynamics(m, ws, Vec4::Zero(), Vec2::Zero(), tau0);
    Vec4 h_a;
    bias_forces(m, ws, h_a);
    CHECK((h_a - tau0).cwiseAbs().maxCoeff() < 1e-9 * (1 + tau0.cwiseAbs().maxCoeff()));
    for (int j = 0; j < kNumActive; ++j) {
      inverse_dynamics(m, ws, Vec4::Unit(j), Vec2::Zero(), tauj);
      CHECK(((tauj - tau0) - M_a.col(j)).cwiseAbs().maxCoeff() < 1e-7 * (1 + M_a.col(j).cwiseAbs().maxCoeff()));
    }
    // Psi^T M_r Psi with the full tree matrix (eq. 17).
    tree_mass_matrix(m, ws, ws.M_r);
    const Mat4 M_full = ws.Psi.transpose() * ws.M_r * ws.Psi;
    CHECK((M_full - M_a).cwiseAbs().maxCoeff() < 1e-8 * M_a.cwiseAbs().maxCoeff());
    const Eigen::SelfAdjointEigenSolver<Mat12> eig_r(ws.M_r);
    CHECK(eig_r.eigenvalues().minCoeff() > 0.0);
  }
}

TEST_CASE("model/the soil force enters inverse dynamics as J_t^T f_soil") {
  const Model& m = reference_model();
  Workspace ws(m);
  test::RandomStates rs(22);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec4 q_a = rs.q_a(m), qd_a = rs.qd_a(), qdd_a = rs.qdd_a();
    REQUIRE(update_closed_chain(m, ws, q_a, qd_a).ok());
    const Vec2 f(rs.uniform(-5e4, 5e4), rs.uniform(-5e4, 5e4));
    Vec4 tau_free, tau_soil;
    inverse_dynamics(m, ws, qdd_a, Vec2::Zero(), tau_free);
    inverse_dynamics(m, ws, qdd_a, f, tau_soil);
    CHECK(((tau_soil - tau_free) - ws.J_t.transpose() * f).cwiseAbs().maxCoeff() < 1e-6 * f.norm());
  }
}

TEST_CASE("model/inverse then forward dynamics round trip") {
  const Model& m = reference_model();
  Workspace ws(m);
  test::RandomStates rs(23);
  for (int trial = 0; trial < 100; ++trial) {
    const Vec4 q_a = rs.q_a(m), qd_a = rs.qd_a(), qdd_a = rs.qdd_a();
    TipLoad load;
    if (trial % 2) {
      load.force = Vec2(rs.uniform(-3e4, 3e4), rs.uniform(-3e4, 3e4));
      load.added_mass = Vec2(rs.uniform(50, 500), rs.uniform(50, 500));
    }
    REQUIRE(update_closed_chain(m, ws, q_a, qd_a).ok());
    // The total soil force for this acceleration (eq. 9): f + M_t rhodd.
    const Vec2 rhodd = ws.J_t * qdd_a + ws.rhodd_bias;
    const Vec2 f_soil = load.force + load.added_mass.cwiseProduct(rhodd);
    Vec4 tau_a, qdd_back;
    inverse_dynamics(m, ws, qdd_a, f_soil, tau_a);
    REQUIRE(forward_dynamics(m, ws, q_a, qd_a, tau_a, load, qdd_back).ok());
    CHECK((qdd_back - qdd_a).cwiseAbs().maxCoeff() < 1e-7);
  }
}

TEST_CASE("model/independent-coordinate and augmented forward dynamics agree") {
  const Model& m = reference_model();
  Workspace ws(m), wa(m);
  test::RandomStates rs(24);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec4 q_a = rs.q_a(m), qd_a = rs.qd_a();
    const Vec4 tau_a(rs.uniform(-6e4, 6e4), rs.uniform(-3e5, 7e5), rs.uniform(-2e5, 4e5), rs.uniform(-1e5, 3e5));
    TipLoad load;
    if (trial % 2) {
      load.force = Vec2(rs.uniform(-3e4, 3e4), rs.uniform(-3e4, 3e4));
      load.added_mass = Vec2(rs.uniform(50, 500), rs.uniform(50, 500));
    }
    Vec4 qdd_a;
    REQUIRE(forward_dynamics(m, ws, q_a, qd_a, tau_a, load, qdd_a).ok());
    Vec12 qdd;
    Vec8 lambda;
    REQUIRE(forward_dynamics_augmented(m, wa, ws.q, ws.qd, tau_a, load, 0.0, 0.0, qdd, lambda).ok());
    const Vec12 qdd_indep = ws.Psi * qdd_a + ws.gamma;
    CHECK((qdd - qdd_indep).cwiseAbs().maxCoeff() < 1e-7 * (1 + qdd_indep.cwiseAbs().maxCoeff()));
    // The multipliers are the loop reaction forces of inverse dynamics at that acceleration.
    const Vec2 f_soil = load.force + load.added_mass.cwiseProduct(ws.J_t * qdd_a + ws.rhodd_bias);
    Vec4 tau_back;
    inverse_dynamics(m, ws, qdd_a, f_soil, tau_back);
    CHECK((tau_back - tau_a).cwiseAbs().maxCoeff() < 1e-6 * tau_a.cwiseAbs().maxCoeff());
    CHECK((lambda - ws.F_c).cwiseAbs().maxCoeff() < 1e-6 * (1 + ws.F_c.cwiseAbs().maxCoeff()));
  }
}

TEST_CASE("model/augmented dynamics with Baumgarte terms pulls a drifted state back to h = 0") {
  const Model& m = reference_model();
  Workspace ws(m), wa(m);
  REQUIRE(update_closed_chain(m, ws, Vec4(0.0, 2.3, 2.7, 2.0), Vec4::Zero()).ok());
  Vec12 q = ws.q, qd = Vec12::Zero();
  q[kBoom] += 1e-3;  // off the constraint manifold
  Vec8 h0;
  loop_residual(m, q, h0);
  REQUIRE(h0.norm() > 1e-4);
  // The actuators hold the pose (static inverse dynamics); semi-implicit Euler for 0.5 s.
  Vec4 hold;
  inverse_dynamics(m, ws, Vec4::Zero(), Vec2::Zero(), hold);
  auto drift_after = [&](double alpha, double beta) {
    Vec12 qk = q, qdk = qd, qdd;
    Vec8 lambda, h;
    const double dt = 1e-3;
    for (int k = 0; k < 500; ++k) {
      REQUIRE(forward_dynamics_augmented(m, wa, qk, qdk, hold, TipLoad{}, alpha, beta, qdd, lambda).ok());
      qdk += qdd * dt;
      qk += qdk * dt;
    }
    loop_residual(m, qk, h);
    return h.norm();
  };
  const double with_baumgarte = drift_after(20.0, 20.0);
  const double without = drift_after(0.0, 0.0);
  CHECK(with_baumgarte < 0.01 * h0.norm());
  CHECK(without > 0.5 * h0.norm());  // eq. 8 as written keeps (or grows) the error
}
