#include "control/task/inverse_kinematics.hpp"

#include <cmath>

namespace exc::control {
namespace {

// Rotation by angle a in the x-z plane, positive turning x towards +z.
Vec2 rotate(double a, const Vec2& p) {
  const double c = std::cos(a), s = std::sin(a);
  return Vec2(c * p.x() - s * p.y(), s * p.x() + c * p.y());
}

double angle_of(const Vec2& v) { return std::atan2(v.y(), v.x()); }

// 2-D cross product (x, z) seen with x right, z up: > 0 when b turns left of a.
double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

}  // namespace

const char* to_string(IkStatus s) {
  switch (s) {
    case IkStatus::ok: return "ok";
    case IkStatus::out_of_reach: return "tip out of reach of boom and arm";
    case IkStatus::no_boom_cylinder: return "degenerate cylinder geometry";
    case IkStatus::no_bucket_link: return "bucket linkage cannot close at this bucket angle";
  }
  return "unknown";
}

IkStatus front_angles_from_tip(const Machine& m, const TipPose& tip, FrontAngles& out) {
  // Everything in the swing frame (origin on the swing axis at swing_height).
  const Vec2 tip_s(tip.x, tip.z - m.swing_height);
  const Vec2 M_s = tip_s - rotate(tip.pitch, m.T);  // T = R(pitch) T_bucket + M
  const Vec2 CM = M_s - m.C;
  // Boom frame x runs along C->H and arm frame x along H->M, so H and M sit on those x axes; their
  // z is kept general (zero for a machine file that follows the frame definition).
  const double l1 = m.H.norm(), l2 = m.M.norm();
  const double d = CM.norm();
  if (!(d <= l1 + l2) || !(d >= std::abs(l1 - l2))) return IkStatus::out_of_reach;
  // Interior angle at H by the law of cosines; the arm bends down (negative arm angle).
  const double c = std::clamp((d * d - l1 * l1 - l2 * l2) / (2 * l1 * l2), -1.0, 1.0);
  const double bend = -std::acos(c);  // angle of H->M relative to C->H (direction vectors)
  const double phi_H = angle_of(m.H), phi_M = angle_of(m.M);  // offsets of H, M from their x axes
  // Direction C->H rotated by 'bend' is direction H->M; solve the boom direction from C->M.
  const double dir_CH = angle_of(CM) - std::atan2(l2 * std::sin(bend), l1 + l2 * std::cos(bend));
  out.boom = dir_CH - phi_H;
  out.arm = (dir_CH + bend) - phi_M - out.boom;
  out.bucket = tip.pitch - out.boom - out.arm;
  return IkStatus::ok;
}

IkStatus cylinder_lengths_from_angles(const Machine& m, const FrontAngles& a, Vec3& lengths) {
  // Boom cylinder: D in the swing frame, E on the boom (boom frame at C, rotated by the boom angle).
  const Vec2 E_s = m.C + rotate(a.boom, m.E);
  lengths[0] = (E_s - m.D).norm();
  // Arm cylinder, in the boom frame: F on the boom, G on the arm (arm frame at H).
  const Vec2 G_b = m.H + rotate(a.arm, m.G);
  lengths[1] = (G_b - m.F).norm();
  if (!(lengths[0] > 0) || !(lengths[1] > 0)) return IkStatus::no_boom_cylinder;
  // Bucket four-bar, in the arm frame: L on the bucket (bucket frame at M). J is at distance JL from
  // L and JK from K; of the two intersections take the branch of the machine's assembly rule (J to
  // the left of the direction I->K); L_bucket = |IJ|.
  const Vec2 L_a = m.M + rotate(a.bucket, m.L);
  const Vec2 LK = m.K - L_a;
  const double d = LK.norm();
  if (!(d < m.JL + m.JK) || !(d > std::abs(m.JL - m.JK))) return IkStatus::no_bucket_link;
  const double along = (m.JL * m.JL - m.JK * m.JK + d * d) / (2 * d);  // from L towards K
  const double h = std::sqrt(std::max(0.0, m.JL * m.JL - along * along));
  const Vec2 u = LK / d;
  const Vec2 n(-u.y(), u.x());  // u turned left
  const Vec2 base = L_a + along * u;
  const Vec2 J1 = base + h * n, J2 = base - h * n;
  const Vec2 IK = m.K - m.I;
  const Vec2 J = cross(IK, J1 - m.I) > 0 ? J1 : J2;
  // The other half of the assembly rule (L to the left of J->M): false past the four-bar's toggle,
  // where the chosen J belongs to the other assembly branch.
  if (!(cross(m.M - J, L_a - J) > 0)) return IkStatus::no_bucket_link;
  lengths[2] = (J - m.I).norm();
  return IkStatus::ok;
}

IkStatus inverse_kinematics(const Machine& m, double swing, const TipPose& tip, Vec4& q_a) {
  FrontAngles a;
  IkStatus s = front_angles_from_tip(m, tip, a);
  if (s != IkStatus::ok) return s;
  Vec3 l;
  s = cylinder_lengths_from_angles(m, a, l);
  if (s != IkStatus::ok) return s;
  q_a << swing, l[0], l[1], l[2];
  return IkStatus::ok;
}

TipPose tip_from_angles(const Machine& m, const FrontAngles& a) {
  const Vec2 H_s = m.C + rotate(a.boom, m.H);
  const Vec2 M_s = H_s + rotate(a.boom + a.arm, m.M);
  const double pitch = a.boom + a.arm + a.bucket;
  const Vec2 T_s = M_s + rotate(pitch, m.T);
  TipPose tip;
  tip.x = T_s.x();
  tip.z = T_s.y() + m.swing_height;
  tip.pitch = pitch;
  return tip;
}

}  // namespace exc::control
