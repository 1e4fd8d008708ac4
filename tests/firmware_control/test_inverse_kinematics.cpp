#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "control/task/inverse_kinematics.hpp"
#include "model/closed_chain.hpp"
#include "model/machine_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {
constexpr double kDeg = 3.14159265358979323846 / 180;
}

TEST_CASE("firmware/inverse kinematics reproduces the reference poses of the machine file") {
  const Machine m = reference_machine();
  REQUIRE(m.reference_poses.size() >= 2);
  for (const ReferencePose& pose : m.reference_poses) {
    // Independent evidence: the published pin positions and angles (4-5 significant digits).
    Vec3 T_world = Vec3::Zero();
    for (const auto& [name, p] : pose.pins_world)
      if (name == "T") T_world = p;
    const double swing = pose.q_a[0];
    TipPose tip;
    tip.x = std::hypot(T_world.x(), T_world.y());
    tip.z = T_world.z();
    tip.pitch = (pose.boom_angle_deg + pose.arm_angle_deg + pose.bucket_angle_deg) * kDeg;
    FrontAngles a;
    REQUIRE(front_angles_from_tip(m, tip, a) == IkStatus::ok);
    CHECK(std::abs(a.boom / kDeg - pose.boom_angle_deg) < 0.01);
    CHECK(std::abs(a.arm / kDeg - pose.arm_angle_deg) < 0.01);
    CHECK(std::abs(a.bucket / kDeg - pose.bucket_angle_deg) < 0.01);
    Vec4 q;
    REQUIRE(inverse_kinematics(m, swing, tip, q) == IkStatus::ok);
    for (int j = 1; j < 4; ++j) CHECK(std::abs(q[j] - pose.q_a[j]) < 5e-4);
  }
}

TEST_CASE("firmware/inverse kinematics round trip through the model's loop closure and tip (sub-mm)") {
  const Model model = build_model(reference_machine());
  const Machine& m = model.machine;
  Workspace ws(model);
  std::mt19937 rng(7);
  const Vec4 lo = m.q_min(), hi = m.q_max();
  int checked = 0;
  for (int k = 0; k < 300; ++k) {
    Vec4 q_a;
    q_a[0] = 0.3;
    for (int j = 1; j < 4; ++j) q_a[j] = std::uniform_real_distribution<double>(lo[j] + 0.02, hi[j] - 0.02)(rng);
    const ModelReport r = update_closed_chain(model, ws, q_a, Vec4::Zero());
    if (!r.ok()) continue;
    // The model's own answer: tip in the swing plane and the three front joint angles.
    TipPose tip;
    tip.x = ws.rho.x();
    tip.z = ws.rho.y();
    tip.pitch = ws.q[kBoom] + ws.q[kArm] + ws.q[kBucket];
    // The planar forward shortcut agrees with the model.
    const TipPose back = tip_from_angles(m, FrontAngles{ws.q[kBoom], ws.q[kArm], ws.q[kBucket]});
    CHECK(std::abs(back.x - tip.x) < 1e-9);
    CHECK(std::abs(back.z - tip.z) < 1e-9);
    Vec4 q_ik;
    REQUIRE(inverse_kinematics(m, q_a[0], tip, q_ik) == IkStatus::ok);
    CHECK((q_ik - q_a).cwiseAbs().maxCoeff() < 1e-7);
    // And back through the model: the tip lands on the target to well under a millimetre.
    REQUIRE(update_closed_chain(model, ws, q_ik, Vec4::Zero()).ok());
    CHECK((ws.rho - Vec2(tip.x, tip.z)).norm() < 1e-6);
    ++checked;
  }
  CHECK(checked > 250);
}

TEST_CASE("firmware/inverse kinematics reports unreachable tips instead of returning garbage") {
  const Machine m = reference_machine();
  Vec4 q;
  CHECK(inverse_kinematics(m, 0, TipPose{30.0, 1.0, 0.0}, q) == IkStatus::out_of_reach);
  CHECK(inverse_kinematics(m, 0, TipPose{0.5, m.swing_height + 0.6, 0.0}, q) == IkStatus::out_of_reach);
  // A bucket angle the linkage cannot reach (bucket turned far past its stroke).
  FrontAngles a{0.5, -1.0, -2.5};
  Vec3 l;
  CHECK(cylinder_lengths_from_angles(m, a, l) == IkStatus::no_bucket_link);
}
