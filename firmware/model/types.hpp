#pragma once
// Fixed-size Eigen types used by the model, the controller and the plant. Nothing here allocates.
#include <Eigen/Core>
#include <array>

namespace exc {

using Vec2 = Eigen::Matrix<double, 2, 1>;
using Vec3 = Eigen::Matrix<double, 3, 1>;
using Vec4 = Eigen::Matrix<double, 4, 1>;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Vec8 = Eigen::Matrix<double, 8, 1>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat2 = Eigen::Matrix<double, 2, 2>;
using Mat3 = Eigen::Matrix<double, 3, 3>;
using Mat4 = Eigen::Matrix<double, 4, 4>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Mat8 = Eigen::Matrix<double, 8, 8>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Mat2x4 = Eigen::Matrix<double, 2, 4>;
using Mat3x4 = Eigen::Matrix<double, 3, 4>;
using Mat8x12 = Eigen::Matrix<double, 8, 12>;
using Mat12x4 = Eigen::Matrix<double, 12, 4>;
using Mat8x4 = Eigen::Matrix<double, 8, 4>;
using Mat4x6 = Eigen::Matrix<double, 4, 6>;  // the soil regressor Y (control/laws/regressor.hpp)
using Mat2x6 = Eigen::Matrix<double, 2, 6>;
using SE3 = Eigen::Matrix<double, 4, 4>;  // homogeneous transform
using Twist = Vec6;                       // (w, v): angular first, as in the paper
using Wrench = Vec6;                      // (m, f): moment first

constexpr int kNumJoints = 12;
constexpr int kNumActive = 4;
constexpr int kNumPassive = 8;
constexpr int kNumLoops = 4;

// Tree joint index (0-based) = paper link number k - 1 (Table 1).
enum JointIndex : int {
  kSwing = 0,         // 1 upper structure, revolute about world z, ACTIVE
  kBoom = 1,          // 2 boom, revolute at the boom foot pin C
  kBoomBarrel = 2,    // 3 boom cylinder barrel, revolute at D
  kBoomRod = 3,       // 4 boom cylinder rod, prismatic, ACTIVE (q = L_boom)
  kArmBarrel = 4,     // 5 arm cylinder barrel, revolute at F
  kArm = 5,           // 6 arm, revolute at H
  kBucket = 6,        // 7 bucket, revolute at M
  kArmRod = 7,        // 8 arm cylinder rod, prismatic, ACTIVE (q = L_arm)
  kBucketBarrel = 8,  // 9 bucket cylinder barrel, revolute at I
  kBucketRod = 9,     // 10 bucket cylinder rod, prismatic, ACTIVE (q = L_bucket)
  kLink11 = 10,       // 11 H-link (rod end J to bucket pin L)
  kLink12 = 11,       // 12 side link (rod end J to arm pin K)
};

// Active coordinates q_a = [theta_swing, L_boom, L_arm, L_bucket] map to these tree joints.
constexpr std::array<int, kNumActive> kActiveJoints = {kSwing, kBoomRod, kArmRod, kBucketRod};
constexpr std::array<int, kNumPassive> kPassiveJoints = {kBoom,   kBoomBarrel,   kArmBarrel, kArm,
                                                         kBucket, kBucketBarrel, kLink11,    kLink12};
// Names of the active axes, in q_a order (used by every tool's output).
constexpr std::array<const char*, kNumActive> kActiveNames = {"swing", "boom", "arm", "bucket"};

}  // namespace exc
