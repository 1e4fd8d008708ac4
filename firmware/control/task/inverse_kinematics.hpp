#pragma once
// Closed-form inverse kinematics of the front, in the model's frame conventions (docs/model.md):
// each front joint angle is its link's x axis relative to the parent's x axis, counter-clockwise
// seen with x forward and z up; boom frame at C with x along C->H, arm frame at H with x along
// H->M, bucket frame at M with x along M->L; the tip T is a point of the bucket frame.
//   tip (x, z) + bucket pitch  -> boom, arm, bucket angles   (planar 3-link: M from the pitch, then
//                                                              the C-H-M triangle, arm bent down)
//   angles                      -> L_boom, L_arm             (the D-C-E and F-H-G triangles: the
//                                                              rod-end pin placed by the angle)
//   bucket angle                -> L_bucket                  (the four-bar I-J-K + J-L-M inverted:
//                                                              J from circles about L and K)
// Pure geometry on the Machine's pins: no allocation, no exceptions; outcomes are typed.
#include "model/machine.hpp"

namespace exc::control {

// A bucket pose in the swing plane.
struct TipPose {
  double x = 0;      // horizontal distance of the tip from the swing axis (m)
  double z = 0;      // world height of the tip (m)
  double pitch = 0;  // angle of M->L above the swing frame's x axis (rad) = boom + arm + bucket
};

struct FrontAngles {
  double boom = 0, arm = 0, bucket = 0;  // rad, the model's passive joint values
};

enum class IkStatus {
  ok = 0,
  out_of_reach,     // C-M distance outside the boom+arm triangle (too far or too close)
  no_boom_cylinder, // degenerate boom/arm cylinder geometry (never for a sane machine)
  no_bucket_link,   // the bucket linkage cannot close: circles about L and K do not meet
};
const char* to_string(IkStatus s);

// Tip pose -> boom, arm, bucket joint angles (arm angle negative: the arm hangs below the boom).
IkStatus front_angles_from_tip(const Machine& machine, const TipPose& tip, FrontAngles& angles);

// Joint angles -> the three cylinder lengths [L_boom, L_arm, L_bucket] (m), pin to pin.
IkStatus cylinder_lengths_from_angles(const Machine& machine, const FrontAngles& angles,
                                      Vec3& lengths);

// Both steps: q_a = [swing, L_boom, L_arm, L_bucket].
IkStatus inverse_kinematics(const Machine& machine, double swing, const TipPose& tip, Vec4& q_a);

// Forward kinematics by the same planar geometry (for checks and for the dig path's reporting):
// angles -> tip pose. The model's loop closure is the reference; this is its planar shortcut.
TipPose tip_from_angles(const Machine& machine, const FrontAngles& angles);

}  // namespace exc::control
