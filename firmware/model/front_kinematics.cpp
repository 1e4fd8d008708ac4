// Planar front kinematics (see front_kinematics.hpp). In the swing plane a rotation by +phi turns
// x toward +z, so a point r fixed in a link turning at omega moves at omega * perp(r).
#include "front_kinematics.hpp"

#include <cmath>

#include "sin_cos.hpp"

namespace exc {

namespace {
inline Vec2 perp(const Vec2& r) { return Vec2(-r.y(), r.x()); }
inline Vec2 rotate(double c, double s, const Vec2& r) { return Vec2(c * r.x() - s * r.y(), s * r.x() + c * r.y()); }
// Rotation by the angle of link i (cosine and sine computed once in front_positions).
inline Vec2 rotate_by(const Workspace& ws, int i, const Vec2& r) { return rotate(ws.cos_phi[i], ws.sin_phi[i], r); }
inline Vec2 planar(const Vec3& p) { return Vec2(p.x(), p.z()); }
// Joint 0 (swing) is the base of the planar front: its children hang off the swing frame.
inline bool in_front(int i) { return i > 0; }
}  // namespace

void front_positions(const Model& model, const Vec12& q, Workspace& ws) {
  for (int i = 1; i < kNumJoints; ++i) {
    if (model.prismatic[i]) {
      ws.joint_cos[i] = 1.0;
      ws.joint_sin[i] = 0.0;
    } else {
      sin_cos(q[i], &ws.joint_sin[i], &ws.joint_cos[i]);
    }
  }
  front_positions_from_joint_trig(model, q, ws);
}

void front_positions_from_joint_trig(const Model& model, const Vec12& q, Workspace& ws) {
  ws.pin_valid = false;  // f_parent no longer matches joint_cos, joint_sin
  ws.cos_phi[0] = 1;
  ws.sin_phi[0] = 0;
  ws.origin[0].setZero();
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    const Vec2 offset = planar(model.home[i].topRightCorner<3, 1>());
    if (model.prismatic[i]) {
      ws.cos_phi[i] = ws.cos_phi[p];
      ws.sin_phi[i] = ws.sin_phi[p];
      ws.origin[i] = ws.origin[p] + rotate_by(ws, p, offset + Vec2(q[i], 0.0));
    } else {
      // phi_i = phi_p + q_i by the angle-sum formulas: no trig per link.
      const double c = ws.joint_cos[i], s = ws.joint_sin[i];
      ws.cos_phi[i] = ws.cos_phi[p] * c - ws.sin_phi[p] * s;
      ws.sin_phi[i] = ws.sin_phi[p] * c + ws.cos_phi[p] * s;
      ws.origin[i] = ws.origin[p] + rotate_by(ws, p, offset);
    }
  }
}

void front_rates(const Model& model, const Vec12& qd, const Vec12& qdd, Workspace& ws) {
  ws.omega[0] = ws.alpha[0] = 0;
  ws.origin_d[0].setZero();
  ws.origin_dd[0].setZero();
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    const Vec2 r = ws.origin[i] - ws.origin[p];
    const double w = ws.omega[p], a = ws.alpha[p];
    Vec2 v = ws.origin_d[p] + w * perp(r);
    Vec2 acc = ws.origin_dd[p] + a * perp(r) - w * w * r;
    if (model.prismatic[i]) {
      const Vec2 u(ws.cos_phi[i], ws.sin_phi[i]);
      v += u * qd[i];
      acc += u * qdd[i] + 2.0 * w * perp(u) * qd[i];  // Coriolis of a slider on a turning link
      ws.omega[i] = w;
      ws.alpha[i] = a;
    } else {
      ws.omega[i] = w + qd[i];
      ws.alpha[i] = a + qdd[i];
    }
    ws.origin_d[i] = v;
    ws.origin_dd[i] = acc;
  }
}

Vec2 front_point(const Workspace& ws, int link, const Vec3& local) {
  return ws.origin[link] + rotate_by(ws, link, planar(local));
}

namespace {
// d(point)/dq_j for every joint j on the path from 'link' to the swing, scaled by 'sign'.
template <int Rows>
void add_point_jacobian(const Model& model, const Workspace& ws, int link, const Vec2& point, double sign,
                        int row, Eigen::Matrix<double, Rows, 12>& J) {
  for (int j = link; in_front(j); j = model.parent[j]) {
    if (model.prismatic[j])
      J.template block<2, 1>(row, j) += sign * Vec2(ws.cos_phi[j], ws.sin_phi[j]);
    else
      J.template block<2, 1>(row, j) += sign * perp(point - ws.origin[j]);
  }
}

Vec2 point_acceleration(const Workspace& ws, int link, const Vec3& local) {
  const Vec2 r = rotate_by(ws, link, planar(local));
  const double w = ws.omega[link];
  return ws.origin_dd[link] + ws.alpha[link] * perp(r) - w * w * r;
}
}  // namespace

void front_loop_residual(const Model& model, const Workspace& ws, Vec8& h) {
  for (int l = 0; l < kNumLoops; ++l) {
    const LoopCut& c = model.loops[l];
    h.segment<2>(2 * l) = front_point(ws, c.link_p, c.point_p) - front_point(ws, c.link_s, c.point_s);
  }
}

void front_loop_jacobian(const Model& model, const Workspace& ws, Mat8x12& H) {
  H.setZero();
  for (int l = 0; l < kNumLoops; ++l) {
    const LoopCut& c = model.loops[l];
    add_point_jacobian<8>(model, ws, c.link_p, front_point(ws, c.link_p, c.point_p), +1.0, 2 * l, H);
    add_point_jacobian<8>(model, ws, c.link_s, front_point(ws, c.link_s, c.point_s), -1.0, 2 * l, H);
  }
}

void front_loop_acceleration(const Model& model, const Workspace& ws, Vec8& hdd) {
  for (int l = 0; l < kNumLoops; ++l) {
    const LoopCut& c = model.loops[l];
    hdd.segment<2>(2 * l) = point_acceleration(ws, c.link_p, c.point_p) - point_acceleration(ws, c.link_s, c.point_s);
  }
}

void front_tip(const Model& model, const Workspace& ws, Vec2& p, Eigen::Matrix<double, 2, 12>& J, Vec2& acc) {
  p = front_point(ws, kBucket, model.tip_in_bucket);
  J.setZero();
  add_point_jacobian<2>(model, ws, kBucket, p, 1.0, 0, J);
  acc = point_acceleration(ws, kBucket, model.tip_in_bucket);
}

}  // namespace exc
