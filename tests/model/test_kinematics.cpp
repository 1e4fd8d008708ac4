// Loop closure and kinematics: the reference poses, closed form against Newton, the planar loop
// residual against the 3-D tree transforms, Psi, gamma and J_t against finite differences, and the
// typed errors for states with no assembly or near the four-bar toggle.
#include <doctest/doctest.h>

#include "model/front_kinematics.hpp"
#include "model/lie_group.hpp"
#include "model/newton_euler.hpp"
#include "model/reference_poses.hpp"
#include "model_fixture.hpp"

using namespace exc;
using exc::test::reference_model;

namespace {
constexpr double kDeg = 180.0 / M_PI;
}  // namespace

TEST_CASE("model/both reference poses are reproduced (0.5 mm, 0.01 deg)") {
  const Model& m = reference_model();
  Workspace ws(m);
  REQUIRE(m.machine.reference_poses.size() == 2);
  for (const ReferencePose& pose : m.machine.reference_poses) {
    CAPTURE(pose.q_a.transpose());
    REQUIRE(update_closed_chain(m, ws, pose.q_a, Vec4::Zero()).ok());
    tree_world_poses(m, ws);
    CHECK(std::abs(ws.q[kBoom] * kDeg - pose.boom_angle_deg) < 0.01);
    CHECK(std::abs(ws.q[kArm] * kDeg - pose.arm_angle_deg) < 0.01);
    CHECK(std::abs(ws.q[kBucket] * kDeg - pose.bucket_angle_deg) < 0.01);
    REQUIRE(pose.pins_world.size() == 8);
    for (const auto& [name, p] : pose.pins_world) {
      CAPTURE(name);
      CHECK((pin_in_world(m, ws, name) - p).norm() < 0.5e-3);
    }
    // The cut pins really meet in 3-D: the other side of each loop reaches the same world point.
    const Vec3 E_on_boom = (ws.X_Wi[kBoom] * Eigen::Vector4d(m.machine.E.x(), 0, m.machine.E.y(), 1)).head<3>();
    CHECK((E_on_boom - pin_in_world(m, ws, "E")).norm() < 1e-12);
    const Vec3 L_on_link = (ws.X_Wi[kLink11] * Eigen::Vector4d(m.machine.JL, 0, 0, 1)).head<3>();
    CHECK((L_on_link - pin_in_world(m, ws, "L")).norm() < 1e-12);
  }
}

TEST_CASE("model/update_closed_chain without the passive angles gives the same model bit for bit, and NaN where the angles were") {
  // The angles are for a reported state; every algorithm works from the pins' cos and sin. A
  // function that read an angle would carry the NaN into its result and fail the comparisons.
  const Model& m = reference_model();
  Workspace with(m), without(m);
  test::RandomStates rs(29);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec4 q_a = rs.q_a(m), qd_a = rs.qd_a(), qdd_a = rs.qdd_a();
    CAPTURE(trial);
    REQUIRE(update_closed_chain(m, with, q_a, qd_a).ok());
    REQUIRE(update_closed_chain(m, without, q_a, qd_a, PassiveAngles::skipped).ok());
    for (int k : kPassiveJoints) {
      CHECK(std::isfinite(with.q[k]));
      CHECK(std::isnan(without.q[k]));
    }
    for (int k : kActiveJoints) CHECK(without.q[k] == with.q[k]);
    CHECK(without.Psi == with.Psi);
    CHECK(without.gamma == with.gamma);
    CHECK(without.J_t == with.J_t);
    CHECK(without.rho == with.rho);
    CHECK(without.rhod == with.rhod);
    CHECK(without.rhodd_bias == with.rhodd_bias);
    Mat4 M_with, M_without;
    Vec4 h_with, h_without, tau_with, tau_without;
    mass_matrix(m, with, M_with);
    mass_matrix(m, without, M_without);
    bias_forces(m, with, h_with);
    bias_forces(m, without, h_without);
    inverse_dynamics(m, with, qdd_a, Vec2(1e4, -2e4), tau_with);
    inverse_dynamics(m, without, qdd_a, Vec2(1e4, -2e4), tau_without);
    CHECK(M_without == M_with);
    CHECK(h_without == h_with);
    CHECK(tau_without == tau_with);
    CHECK(without.F_c == with.F_c);
  }
}

TEST_CASE("model/closed-form and Newton loop closure agree") {
  const Model& m = reference_model();
  Workspace ws(m), wn(m);
  test::RandomStates rs(11);
  for (int trial = 0; trial < 200; ++trial) {
    const Vec4 q_a = rs.q_a(m);
    REQUIRE(solve_loop_closure(m, ws, q_a).ok());
    Vec8 h;
    loop_residual(m, ws.q, h);
    CHECK(h.cwiseAbs().maxCoeff() < 1e-12);
    // Newton from a perturbed guess (0.05 rad on every passive joint) lands on the same branch.
    wn.q = ws.q;
    for (int k : kPassiveJoints) wn.q[k] += rs.uniform(-0.05, 0.05);
    const ModelReport r = solve_loop_closure_newton(m, wn, q_a);
    REQUIRE(r.ok());
    CHECK((wn.q - ws.q).cwiseAbs().maxCoeff() < 1e-10);
  }
}

TEST_CASE("model/the planar loop residual equals the 3-D tree transforms") {
  const Model& m = reference_model();
  Workspace ws(m);
  test::RandomStates rs(12);
  for (int trial = 0; trial < 50; ++trial) {
    Vec12 q;  // an arbitrary, unclosed tree configuration
    for (int i = 0; i < kNumJoints; ++i) q[i] = m.prismatic[i] ? rs.uniform(1.5, 3.0) : rs.uniform(-2, 2);
    Vec8 h;
    loop_residual(m, q, h);
    tree_kinematics(m, ws, q, Vec12::Zero());
    const Mat3 R_sw = rotation(ws.X_Wi[kSwing]);
    for (int l = 0; l < kNumLoops; ++l) {
      const LoopCut& c = m.loops[l];
      const Vec3 p = (ws.X_Wi[c.link_p] * c.point_p.homogeneous()).head<3>();
      const Vec3 s = (ws.X_Wi[c.link_s] * c.point_s.homogeneous()).head<3>();
      const Vec3 d = R_sw.transpose() * (p - s);  // in the swing frame
      CHECK(std::abs(d.y()) < 1e-12);             // the front is planar
      CHECK(std::abs(d.x() - h[2 * l]) < 1e-12);
      CHECK(std::abs(d.z() - h[2 * l + 1]) < 1e-12);
    }
  }
}

namespace {
// A tree state with every joint anywhere (slides within 1.5-3 m): no loop closure needed.
void random_tree_state(const Model& m, test::RandomStates& rs, Vec12& q, Vec12& qd, Vec12& qdd) {
  for (int i = 0; i < kNumJoints; ++i) {
    q[i] = m.prismatic[i] ? rs.uniform(1.5, 3.0) : rs.uniform(-M_PI, M_PI);
    qd[i] = rs.uniform(-1, 1);
    qdd[i] = rs.uniform(-2, 2);
  }
}

// The planar front pass into 'fast' and the general Lie-group pass into 'general', at the same state.
void both_tree_passes(const Model& m, const Vec12& q, const Vec12& qd, Workspace& fast, Workspace& general) {
  fast.q = q;
  front_positions(m, q, fast);
  tree_kinematics_from_front(m, fast, qd);
  tree_kinematics(m, general, q, qd);
}
}  // namespace

TEST_CASE("model/tree kinematics from the planar front pass equals the general Lie-group pass") {
  const Model& m = reference_model();
  REQUIRE(m.planar_front);  // else the comparison below would test the fallback against itself
  Workspace fast(m), general(m);
  test::RandomStates rs(31);
  for (int trial = 0; trial < 200; ++trial) {
    Vec12 q, qd, qdd;  // arbitrary tree states: the fast pass needs no loop closure
    random_tree_state(m, rs, q, qd, qdd);
    both_tree_passes(m, q, qd, fast, general);
    CHECK_FALSE(fast.front_world_poses_valid);
    tree_world_poses(m, fast);
    for (int i = 0; i < kNumJoints; ++i) {
      CHECK((fast.X_Wi[i] - general.X_Wi[i]).cwiseAbs().maxCoeff() < 1e-12);
      CHECK((fast.f_parent[i] - general.f_parent[i]).cwiseAbs().maxCoeff() < 1e-12);
      CHECK((fast.V[i] - general.V[i]).cwiseAbs().maxCoeff() < 1e-12);
    }
    CHECK((fast.tip_world - general.tip_world).norm() < 1e-12);
  }
  // A home with an out-of-plane offset (a barrel pinned beside the boom) takes the same path.
  Machine shifted = m.machine;
  Model m2 = build_model(shifted);
  m2.home[kBoomBarrel](1, 3) += 0.15;
  Workspace f2(m2), g2(m2);
  Vec12 q = Vec12::Constant(0.3), qd = Vec12::Constant(0.2);
  for (int i = 0; i < kNumJoints; ++i)
    if (m2.prismatic[i]) q[i] = 2.0;
  f2.q = q;
  front_positions(m2, q, f2);
  tree_kinematics_from_front(m2, f2, qd);
  tree_kinematics(m2, g2, q, qd);
  tree_world_poses(m2, f2);
  for (int i = 0; i < kNumJoints; ++i) CHECK((f2.X_Wi[i] - g2.X_Wi[i]).cwiseAbs().maxCoeff() < 1e-12);
}

TEST_CASE("model/Newton-Euler and M_r on the pin transforms equal the general Lie-group pass") {
  const Model& m = reference_model();
  REQUIRE(m.planar_front);
  Workspace fast(m), general(m);
  test::RandomStates rs(37);
  for (int trial = 0; trial < 100; ++trial) {
    Vec12 q, qd, qdd;
    random_tree_state(m, rs, q, qd, qdd);
    both_tree_passes(m, q, qd, fast, general);
    REQUIRE(fast.pin_valid);
    REQUIRE_FALSE(general.pin_valid);
    const Vec2 f_soil(rs.uniform(-5e4, 5e4), rs.uniform(-5e4, 5e4));
    Vec12 tau_fast, tau_general;
    tree_inverse_dynamics(m, fast, qdd, f_soil, tau_fast);
    tree_inverse_dynamics(m, general, qdd, f_soil, tau_general);
    CHECK((tau_fast - tau_general).cwiseAbs().maxCoeff() < 1e-9 * (1 + tau_general.cwiseAbs().maxCoeff()));
    Mat12 M_fast, M_general;
    tree_mass_matrix(m, fast, M_fast);
    tree_mass_matrix(m, general, M_general);
    CHECK((M_fast - M_general).cwiseAbs().maxCoeff() < 1e-9 * (1 + M_general.cwiseAbs().maxCoeff()));
  }
  // After new positions the pin transforms are stale until the tree pass runs again.
  front_positions(m, Vec12::Constant(2.0), fast);
  CHECK_FALSE(fast.pin_valid);
}

TEST_CASE("model/Psi, gamma and the tip Jacobian match finite differences of the loop closure") {
  const Model& m = reference_model();
  Workspace ws(m), wp(m), wm(m);
  test::RandomStates rs(13);
  for (int trial = 0; trial < 50; ++trial) {
    const Vec4 q_a = rs.q_a(m), qd_a = rs.qd_a();
    REQUIRE(update_closed_chain(m, ws, q_a, qd_a).ok());
    const double eps = 1e-6;
    for (int j = 0; j < kNumActive; ++j) {
      const Vec4 dq = Vec4::Unit(j) * eps;
      REQUIRE(update_closed_chain(m, wp, q_a + dq, Vec4::Zero()).ok());
      REQUIRE(update_closed_chain(m, wm, q_a - dq, Vec4::Zero()).ok());
      const Vec12 col = (wp.q - wm.q) / (2 * eps);
      CHECK((col - ws.Psi.col(j)).cwiseAbs().maxCoeff() < 1e-6);
      const Vec2 dtip = (wp.rho - wm.rho) / (2 * eps);
      CHECK((dtip - ws.J_t.col(j)).cwiseAbs().maxCoeff() < 1e-6);
    }
    // Along q_a(t) = q_a + qd_a t: q(t) has second derivative gamma (qdd_a = 0) and the tip rho
    // has second derivative rhodd_bias.
    const double h = 1e-4;
    REQUIRE(update_closed_chain(m, wp, q_a + qd_a * h, Vec4::Zero()).ok());
    REQUIRE(update_closed_chain(m, wm, q_a - qd_a * h, Vec4::Zero()).ok());
    const Vec12 qdd_fd = (wp.q - 2 * ws.q + wm.q) / (h * h);
    CHECK((qdd_fd - ws.gamma).cwiseAbs().maxCoeff() < 1e-5 * (1 + ws.gamma.cwiseAbs().maxCoeff()));
    const Vec2 rhodd_fd = (wp.rho - 2 * ws.rho + wm.rho) / (h * h);
    CHECK((rhodd_fd - ws.rhodd_bias).cwiseAbs().maxCoeff() < 1e-5 * (1 + ws.rhodd_bias.norm()));
    // rho (z in the world) against the 3-D tip in swing coordinates.
    const Vec3 tip_sw = rotation(ws.X_Wi[kSwing]).transpose() * (ws.tip_world - translation(ws.X_Wi[kSwing]));
    CHECK(std::abs(tip_sw.x() - ws.rho.x()) < 1e-12);
    CHECK(std::abs(tip_sw.z() + m.machine.swing_height - ws.rho.y()) < 1e-12);
    CHECK(ws.J_t.col(0).norm() == 0.0);
  }
}

TEST_CASE("model/no-assembly and four-bar toggle states give typed errors, never NaN") {
  const Model& m = reference_model();
  Workspace ws(m);
  const Vec4 good(0.0, 2.4, 2.6, 2.0);
  REQUIRE(update_closed_chain(m, ws, good, Vec4::Zero()).ok());
  const Vec12 q_before = ws.q;

  SUBCASE("boom cylinder longer than its triangle allows") {
    const ModelReport r = update_closed_chain(m, ws, Vec4(0.0, 3.5, 2.6, 2.0), Vec4::Zero());
    CHECK(r.status == ModelStatus::no_assembly);
    CHECK(r.loop == 0);
  }
  SUBCASE("arm cylinder shorter than its triangle allows") {
    const ModelReport r = update_closed_chain(m, ws, Vec4(0.0, 2.4, 1.0, 2.0), Vec4::Zero());
    CHECK(r.status == ModelStatus::no_assembly);
    CHECK(r.loop == 1);
  }
  SUBCASE("bucket cylinder past the four-bar toggle") {
    const ModelReport r = update_closed_chain(m, ws, Vec4(0.0, 2.4, 2.6, 1.55), Vec4::Zero());
    CHECK(r.status == ModelStatus::no_assembly);
    CHECK(r.loop == 3);
  }
  SUBCASE("bucket cylinder at the four-bar toggle (L_bucket ~1.58 m)") {
    const ModelReport r = update_closed_chain(m, ws, Vec4(0.0, 2.4, 2.6, 1.5825), Vec4::Zero());
    CHECK(r.status == ModelStatus::near_toggle);
    CHECK(r.loop == 3);
    CHECK(r.conditioning > 0.0);
    CHECK(r.conditioning < 0.1);
    // Newton from the last good state reports it too (H_p ill-conditioned or no convergence).
    Workspace wn(m);
    REQUIRE(solve_loop_closure(m, wn, Vec4(0.0, 2.4, 2.6, 1.59)).ok());
    const ModelReport rn = solve_loop_closure_newton(m, wn, Vec4(0.0, 2.4, 2.6, 1.5805));
    CHECK(rn.status != ModelStatus::ok);
  }
  SUBCASE("a NaN input") {
    const ModelReport r = update_closed_chain(m, ws, Vec4(0.0, NAN, 2.6, 2.0), Vec4::Zero());
    CHECK(r.status == ModelStatus::non_finite_input);
  }
  // The workspace keeps the last good state: no NaN leaks to a caller that ignores the status.
  CHECK(ws.q.allFinite());
  CHECK(ws.q == q_before);
  Vec4 qdd;
  const ModelReport r = forward_dynamics(m, ws, Vec4(0.0, 2.4, 2.6, 1.5), Vec4::Zero(), Vec4::Zero(), TipLoad{}, qdd);
  CHECK(r.status == ModelStatus::no_assembly);
}

TEST_CASE("model/the whole stroke box assembles with usable conditioning") {
  const Model& m = reference_model();
  Workspace ws(m);
  const Vec4 lo = m.machine.q_min(), hi = m.machine.q_max();
  double worst = 1.0;
  for (int i = 0; i <= 8; ++i)
    for (int j = 0; j <= 8; ++j)
      for (int k = 0; k <= 8; ++k) {
        const Vec4 q_a(0.0, lo[1] + (hi[1] - lo[1]) * i / 8.0, lo[2] + (hi[2] - lo[2]) * j / 8.0,
                       lo[3] + (hi[3] - lo[3]) * k / 8.0);
        const ModelReport r = update_closed_chain(m, ws, q_a, Vec4::Zero());
        REQUIRE(r.ok());
        worst = std::min(worst, r.conditioning);
      }
  CHECK(worst > 0.05);
}
