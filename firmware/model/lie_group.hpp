#pragma once
// SE(3) and se(3) with fixed-size Eigen (model.md s.3): hat maps, exp, Ad, ad and their duals.
// Twists are (w, v) and wrenches (m, f), angular part first, as in the paper. Nothing allocates.
#include <cmath>

#include <Eigen/Geometry>

#include "types.hpp"

namespace exc {

// [w]: the skew-symmetric matrix with [w] x = w x x.
inline Mat3 skew(const Vec3& w) {
  Mat3 s;
  s << 0, -w.z(), w.y(), w.z(), 0, -w.x(), -w.y(), w.x(), 0;
  return s;
}

inline Mat3 rotation(const SE3& T) { return T.topLeftCorner<3, 3>(); }
inline Vec3 translation(const SE3& T) { return T.topRightCorner<3, 1>(); }

inline SE3 make_se3(const Mat3& R, const Vec3& p) {
  SE3 T = SE3::Identity();
  T.topLeftCorner<3, 3>() = R;
  T.topRightCorner<3, 1>() = p;
  return T;
}

inline SE3 translation_se3(const Vec3& p) { return make_se3(Mat3::Identity(), p); }

// T^-1 = (R^T, -R^T p), without a general 4x4 inverse.
inline SE3 inverse(const SE3& T) {
  const Mat3 Rt = rotation(T).transpose();
  return make_se3(Rt, -Rt * translation(T));
}

// [S]: the 4x4 matrix of a twist in se(3).
inline SE3 hat(const Twist& S) {
  SE3 m = SE3::Zero();
  m.topLeftCorner<3, 3>() = skew(S.head<3>());
  m.topRightCorner<3, 1>() = S.tail<3>();
  return m;
}

// exp([S] q) in closed form (Rodrigues for the rotation, the matching V matrix for the translation).
inline SE3 exp_se3(const Twist& S, double q) {
  const Vec3 w = S.head<3>() * q;
  const Vec3 v = S.tail<3>() * q;
  const double th = w.norm();
  if (th < 1e-12) {
    // Pure translation (prismatic) or a vanishing angle: first order is exact to rounding.
    return make_se3(Mat3::Identity() + skew(w), v);
  }
  const Mat3 K = skew(w / th);
  const double s = std::sin(th), c = std::cos(th);
  const Mat3 R = Mat3::Identity() + s * K + (1 - c) * K * K;
  const Mat3 V = Mat3::Identity() + ((1 - c) / th) * K + ((th - s) / th) * K * K;
  return make_se3(R, V * v);
}

// A * B by blocks (R_A R_B, R_A p_B + p_A): a quarter of the work of a 4x4 product.
inline SE3 compose(const SE3& A, const SE3& B) {
  const Mat3 R_A = rotation(A);
  return make_se3(R_A * rotation(B), R_A * translation(B) + translation(A));
}

// exp([S] q) for a joint screw: a unit rotation axis through the origin (w, 0) or a unit slide
// (0, v). Rodrigues as R = c I + s [w] + (1 - c) w w^T; equals exp_se3 for these screws.
inline SE3 joint_motion(const Twist& S, double q, bool prismatic) {
  if (prismatic) return translation_se3(S.tail<3>() * q);
  const Vec3 w = S.head<3>();
  const double s = std::sin(q), c = std::cos(q), k = 1 - c;
  SE3 T;
  T << c + k * w.x() * w.x(), k * w.x() * w.y() - s * w.z(), k * w.x() * w.z() + s * w.y(), 0,
      k * w.x() * w.y() + s * w.z(), c + k * w.y() * w.y(), k * w.y() * w.z() - s * w.x(), 0,
      k * w.x() * w.z() - s * w.y(), k * w.y() * w.z() + s * w.x(), c + k * w.z() * w.z(), 0,
      0, 0, 0, 1;
  return T;
}

// Ad_T (6x6): maps a twist in frame B to frame A for T = X_AB.
inline Mat6 Ad(const SE3& T) {
  const Mat3 R = rotation(T);
  Mat6 A = Mat6::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.bottomRightCorner<3, 3>() = R;
  A.bottomLeftCorner<3, 3>() = skew(translation(T)) * R;
  return A;
}

// ad_V (6x6): the Lie bracket [V, .] of se(3).
inline Mat6 ad(const Twist& V) {
  Mat6 a = Mat6::Zero();
  a.topLeftCorner<3, 3>() = skew(V.head<3>());
  a.bottomRightCorner<3, 3>() = skew(V.head<3>());
  a.bottomLeftCorner<3, 3>() = skew(V.tail<3>());
  return a;
}

// The vector forms below run 10^2 times per dynamics call: forced inline, and written on blocks of the
// 4x4 transform so no rotation is copied out.
#define EXC_HOT_INLINE [[gnu::always_inline]] inline

// Ad_T V without forming the 6x6 matrix.
EXC_HOT_INLINE Twist Ad_apply(const SE3& T, const Twist& V) {
  const Vec3 w = T.topLeftCorner<3, 3>() * V.head<3>();
  const Vec3 p = T.topRightCorner<3, 1>();
  Twist out;
  out.head<3>() = w;
  out.tail<3>() = p.cross(w) + T.topLeftCorner<3, 3>() * V.tail<3>();
  return out;
}

// Ad_{T^-1} V: a twist of frame A expressed in frame B, for T = X_AB (the forward pass of eq. 1).
EXC_HOT_INLINE Twist Ad_inv_apply(const SE3& T, const Twist& V) {
  const Vec3 p = T.topRightCorner<3, 1>();
  const Vec3 w = V.head<3>();
  const Vec3 v = V.tail<3>() - p.cross(w);
  Twist out;
  out.head<3>().noalias() = T.topLeftCorner<3, 3>().transpose() * w;
  out.tail<3>().noalias() = T.topLeftCorner<3, 3>().transpose() * v;
  return out;
}

// Ad*_{T^-1} F = Ad_{T^-1}^T F: a wrench in frame B expressed in frame A, for T = X_AB
// (the backward pass of eq. 1 with T = f_{i,k}).
EXC_HOT_INLINE Wrench Ad_inv_dual_apply(const SE3& T, const Wrench& F) {
  const Vec3 p = T.topRightCorner<3, 1>();
  const Vec3 f = T.topLeftCorner<3, 3>() * F.tail<3>();
  const Vec3 m = T.topLeftCorner<3, 3>() * F.head<3>();
  Wrench out;
  out.head<3>() = m + p.cross(f);
  out.tail<3>() = f;
  return out;
}

// The same two maps for T = (R, p) with R the rotation about -y of cosine c and sine s (x turns
// toward +z): every joint of the planar front. A third of the multiplications of the general form.
EXC_HOT_INLINE Twist Ad_inv_apply_pin(double c, double s, const Vec3& p, const Twist& V) {
  const double wx = V[0], wy = V[1], wz = V[2];
  const double vx = V[3] - (p.y() * wz - p.z() * wy);  // v - p x w
  const double vy = V[4] - (p.z() * wx - p.x() * wz);
  const double vz = V[5] - (p.x() * wy - p.y() * wx);
  Twist out;
  out << c * wx + s * wz, wy, c * wz - s * wx, c * vx + s * vz, vy, c * vz - s * vx;
  return out;
}

EXC_HOT_INLINE Wrench Ad_inv_dual_apply_pin(double c, double s, const Vec3& p, const Wrench& F) {
  const double fx = c * F[3] - s * F[5], fy = F[4], fz = s * F[3] + c * F[5];  // R f
  Wrench out;
  out << c * F[0] - s * F[2] + (p.y() * fz - p.z() * fy), F[1] + (p.z() * fx - p.x() * fz),
      s * F[0] + c * F[2] + (p.x() * fy - p.y() * fx), fx, fy, fz;
  return out;
}

// ad_V W.
EXC_HOT_INLINE Twist ad_apply(const Twist& V, const Twist& W) {
  const Vec3 vw = V.head<3>(), vv = V.tail<3>(), ww = W.head<3>(), wv = W.tail<3>();
  Twist out;
  out.head<3>() = vw.cross(ww);
  out.tail<3>() = vv.cross(ww) + vw.cross(wv);
  return out;
}

// ad*_V F = ad_V^T F.
EXC_HOT_INLINE Wrench ad_dual_apply(const Twist& V, const Wrench& F) {
  const Vec3 vw = V.head<3>(), vv = V.tail<3>(), fm = F.head<3>(), ff = F.tail<3>();
  Wrench out;
  out.head<3>() = fm.cross(vw) + ff.cross(vv);
  out.tail<3>() = ff.cross(vw);
  return out;
}

// J V for J = spatial_inertia(mass, com, diag(inertia_diag)) without forming J: the linear
// momentum m (v + w x c), then the angular Ic w + c x (m (v + w x c)). Newton-Euler's hot product.
EXC_HOT_INLINE Wrench inertia_apply(double mass, const Vec3& com, const Vec3& inertia_diag, const Twist& V) {
  const Vec3 w = V.head<3>();
  const Vec3 p = mass * (V.tail<3>() + w.cross(com));
  Wrench out;
  out.head<3>() = inertia_diag.cwiseProduct(w) + com.cross(p);
  out.tail<3>() = p;
  return out;
}

// Spatial inertia about the frame origin, twist (w, v): J = [[Ic - m[c]^2, m[c]], [-m[c], m I]].
inline Mat6 spatial_inertia(double mass, const Vec3& com, const Mat3& inertia_about_com) {
  const Mat3 C = skew(com);
  Mat6 J;
  J.topLeftCorner<3, 3>() = inertia_about_com - mass * C * C;
  J.topRightCorner<3, 3>() = mass * C;
  J.bottomLeftCorner<3, 3>() = -mass * C;
  J.bottomRightCorner<3, 3>() = mass * Mat3::Identity();
  return J;
}

}  // namespace exc
