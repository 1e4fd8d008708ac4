// The planar closed-chain pass (see planar_closed_chain.hpp). Everything is in the swing frame S: x
// forward, z up, y out of the plane; a link's angle phi turns its x axis toward +z (a pin about
// -y), so its axes in S are x = (cos phi, 0, sin phi), y = (0, 1, 0), z = (-sin phi, 0, cos phi).
// Loops over links run over the constant tables below and unroll into straight-line code.
#include "planar_closed_chain.hpp"

#include <cmath>

#include "loop_closure.hpp"
#include "sin_cos.hpp"

namespace exc {

namespace {

// The tree the pass is written for (types.hpp, paper Table 1): each joint's parent, and which are
// slides (the cylinders' rods).
constexpr std::array<int, kNumJoints> kParent = {-1,    kSwing,     kSwing,        kBoomBarrel,
                                                 kBoom, kBoom,      kArm,          kArmBarrel,
                                                 kArm,  kBucketBarrel, kBucketRod, kBucketRod};
constexpr std::array<bool, kNumJoints> kSlide = {false, false, false, true,  false, false,
                                                 false, true,  false, true,  false, false};
// The cylinder (1 boom, 2 arm, 3 bucket: a column of q_a) whose rate moves joint i. It is also the
// number of cylinder columns that can move link i: its path from the swing passes the boom's joints
// first, then the arm's, then the bucket's.
constexpr std::array<int, kNumJoints> kCylinder = {0, 1, 1, 1, 2, 2, 3, 2, 3, 3, 3, 3};

inline Vec2 perp(const Vec2& r) { return Vec2(-r.y(), r.x()); }  // turned by +90 degrees
inline double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }
inline Vec2 rotate(double c, double s, const Vec2& r) { return Vec2(c * r.x() - s * r.y(), s * r.x() + c * r.y()); }
inline Vec2 in_plane(const Vec3& p) { return Vec2(p.x(), p.z()); }
inline Vec2 home_in_plane(const Model& m, int i) { return Vec2(m.home[i](0, 3), m.home[i](2, 3)); }
// A point fixed in link i (its x, z), in S.
inline Vec2 point_of(const Workspace& ws, int i, const Vec2& local) {
  return ws.origin[i] + rotate(ws.cos_phi[i], ws.sin_phi[i], local);
}
// x of [a b] x = r (Cramer; the loop closure has refused a singular block).
inline Vec2 solve2(const Vec2& a, const Vec2& b, const Vec2& r) {
  const double inv = 1.0 / cross(a, b);
  return Vec2(cross(r, b) * inv, cross(a, r) * inv);
}

// Absolute angles (their cos, sin) and origins of the links from the pins' cos, sin and the slides'
// lengths (front_positions_from_joint_trig, on the constant tree).
void positions(const Model& m, Workspace& ws) {
  ws.cos_phi[0] = 1;
  ws.sin_phi[0] = 0;
  ws.origin[0].setZero();
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = kParent[i];
    const double cp = ws.cos_phi[p], sp = ws.sin_phi[p];
    Vec2 offset = home_in_plane(m, i);
    if (kSlide[i]) {
      offset.x() += ws.q[i];
      ws.cos_phi[i] = cp;
      ws.sin_phi[i] = sp;
    } else {
      const double c = ws.joint_cos[i], s = ws.joint_sin[i];
      ws.cos_phi[i] = cp * c - sp * s;
      ws.sin_phi[i] = sp * c + cp * s;
    }
    ws.origin[i] = ws.origin[p] + rotate(cp, sp, offset);
  }
}

// Passive joint rates per unit cylinder rate (Psi, eq. 16a) and the passive accelerations at qdd_a = 0
// (gamma), loop by loop. At closure H_p is block diagonal: each loop's velocity constraint involves
// only the joints between its cut pin and the link both its sides hang from, and each block is 2 x 2
// (the four-bar's two loops in turn: link 12's loop first, whose barrel rate enters the bucket's).
// H's column of a pin j at point X is perp(X - o_j), of a slide its axis; + on the pin's side P, - on
// the side S. gamma solves the same blocks for the cut pins' relative acceleration at qdd = 0, taken
// from the loop's own joints with rates relative to its common link (the common link's motion adds
// the same to both sides at closure).
struct LoopRates {
  double psi[kNumJoints] = {};  // passive rows of Psi (each in its cylinder's column); 1 on the slides
  double gamma[kNumJoints] = {};
};

LoopRates loop_rates(const Model& m, Workspace& ws, const Vec4& qd_a) {
  LoopRates r;
  const std::array<Vec2, kNumJoints>& o = ws.origin;
  auto axis = [&ws](int i) { return Vec2(ws.cos_phi[i], ws.sin_phi[i]); };
  Vec12& qd = ws.qd;

  // Loop 0: E on the boom (pin C) <-> the boom rod's end (barrel pin D, slide).
  const Vec2 E = point_of(ws, kBoom, in_plane(m.loops[0].point_p));
  const Vec2 S0 = point_of(ws, kBoomRod, in_plane(m.loops[0].point_s));
  const Vec2 h_boom = perp(E - o[kBoom]), h_boom_barrel = -perp(S0 - o[kBoomBarrel]), u_boom = axis(kBoomRod);
  const Vec2 psi0 = solve2(h_boom, h_boom_barrel, u_boom);
  // Loop 1: G on the arm (pin H) <-> the arm rod's end (barrel pin F, slide); common link the boom.
  const Vec2 G = point_of(ws, kArm, in_plane(m.loops[1].point_p));
  const Vec2 S1 = point_of(ws, kArmRod, in_plane(m.loops[1].point_s));
  const Vec2 h_arm = perp(G - o[kArm]), h_arm_barrel = -perp(S1 - o[kArmBarrel]), u_arm = axis(kArmRod);
  const Vec2 psi1 = solve2(h_arm_barrel, h_arm, u_arm);
  // Loop 2: K on the arm <-> link 12's end (bucket barrel pin I, slide, link 12's pin at J); common
  // link the arm, so K's side has no joint.
  const Vec2 S2 = point_of(ws, kLink12, in_plane(m.loops[2].point_s));
  const Vec2 h_barrel2 = -perp(S2 - o[kBucketBarrel]), h_link12 = -perp(S2 - o[kLink12]), u_bucket = axis(kBucketRod);
  const Vec2 psi2 = solve2(h_barrel2, h_link12, u_bucket);
  // Loop 3: L on the bucket (pin M) <-> link 11's end (the same barrel and slide, link 11's pin at J).
  const Vec2 L = point_of(ws, kBucket, in_plane(m.loops[3].point_p));
  const Vec2 S3 = point_of(ws, kLink11, in_plane(m.loops[3].point_s));
  const Vec2 h_bucket = perp(L - o[kBucket]), h_link11 = -perp(S3 - o[kLink11]), h_barrel3 = -perp(S3 - o[kBucketBarrel]);
  const Vec2 psi3 = solve2(h_bucket, h_link11, u_bucket - h_barrel3 * psi2.x());

  r.psi[kBoom] = psi0.x(), r.psi[kBoomBarrel] = psi0.y(), r.psi[kBoomRod] = 1;
  r.psi[kArmBarrel] = psi1.x(), r.psi[kArm] = psi1.y(), r.psi[kArmRod] = 1;
  r.psi[kBucketBarrel] = psi2.x(), r.psi[kLink12] = psi2.y(), r.psi[kBucketRod] = 1;
  r.psi[kBucket] = psi3.x(), r.psi[kLink11] = psi3.y();
  qd[kSwing] = qd_a[0];
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) qd[i] = r.psi[i] * qd_a[kCylinder[i]];

  // Relative accelerations of the cut pins at qdd = 0: a pin turning at w about X moves a point Y by
  // -w^2 (Y - X); a slide of rate v on a link turning at w adds 2 w v perp(axis) (Coriolis).
  const Vec2 a_S0 = -qd[kBoomBarrel] * qd[kBoomBarrel] * (S0 - o[kBoomBarrel]) +
                    2 * qd[kBoomBarrel] * qd[kBoomRod] * perp(u_boom);
  const Vec2 hd0 = -qd[kBoom] * qd[kBoom] * (E - o[kBoom]) - a_S0;
  const Vec2 a_S1 = -qd[kArmBarrel] * qd[kArmBarrel] * (S1 - o[kArmBarrel]) +
                    2 * qd[kArmBarrel] * qd[kArmRod] * perp(u_arm);
  const Vec2 hd1 = -qd[kArm] * qd[kArm] * (G - o[kArm]) - a_S1;
  const double w_barrel = qd[kBucketBarrel];
  // The bucket rod's end J (link 11's and 12's pins), then each link's end.
  const Vec2 a_J = -w_barrel * w_barrel * (o[kBucketRod] - o[kBucketBarrel]) + 2 * w_barrel * qd[kBucketRod] * perp(u_bucket);
  const double w12 = w_barrel + qd[kLink12], w11 = w_barrel + qd[kLink11];
  const Vec2 a_S2 = a_J - w_barrel * w_barrel * (o[kLink12] - o[kBucketRod]) - w12 * w12 * (S2 - o[kLink12]);
  const Vec2 a_S3 = a_J - w_barrel * w_barrel * (o[kLink11] - o[kBucketRod]) - w11 * w11 * (S3 - o[kLink11]);
  const Vec2 hd2 = -a_S2;
  const Vec2 hd3 = -qd[kBucket] * qd[kBucket] * (L - o[kBucket]) - a_S3;
  const Vec2 g0 = solve2(h_boom, h_boom_barrel, -hd0);
  const Vec2 g1 = solve2(h_arm_barrel, h_arm, -hd1);
  const Vec2 g2 = solve2(h_barrel2, h_link12, -hd2);
  const Vec2 g3 = solve2(h_bucket, h_link11, -hd3 - h_barrel3 * g2.x());
  r.gamma[kBoom] = g0.x(), r.gamma[kBoomBarrel] = g0.y();
  r.gamma[kArmBarrel] = g1.x(), r.gamma[kArm] = g1.y();
  r.gamma[kBucketBarrel] = g2.x(), r.gamma[kLink12] = g2.y();
  r.gamma[kBucket] = g3.x(), r.gamma[kLink11] = g3.y();
  return r;
}

// Each link's angular rate and origin velocity (qd) and, at qdd_a = 0 (qdd = gamma), its angular and
// origin acceleration: front_rates' recursion on the constant tree.
void rates(Workspace& ws, const LoopRates& r) {
  Workspace::PlanarLinks& pl = ws.planar;
  ws.omega[0] = 0;
  pl.alpha[0] = 0;
  ws.origin_d[0].setZero();
  pl.acceleration[0].setZero();
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = kParent[i];
    const Vec2 d = ws.origin[i] - ws.origin[p];
    const double w = ws.omega[p], a = pl.alpha[p];
    Vec2 v = ws.origin_d[p] + w * perp(d);
    Vec2 acc = pl.acceleration[p] + a * perp(d) - w * w * d;
    if (kSlide[i]) {
      const Vec2 u(ws.cos_phi[i], ws.sin_phi[i]);
      v += ws.qd[i] * u;
      acc += 2 * w * ws.qd[i] * perp(u);
      ws.omega[i] = w;
      pl.alpha[i] = a;
    } else {
      ws.omega[i] = w + ws.qd[i];
      pl.alpha[i] = a + r.gamma[i];
    }
    ws.origin_d[i] = v;
    pl.acceleration[i] = acc;
  }
}

// The tree's body twists V_i (the Newton-Euler passes and the kinetic energy read them) and the pin
// transforms f_parent, as tree_kinematics_from_front leaves them. A front link turns at (0, -omega,
// w0) in S and its origin (o, y) moves at (o_d.x - w0 y, w0 o.x, o_d.z) in S.
void twists(const Model& m, Workspace& ws) {
  const double w0 = ws.qd[kSwing];
  double s0, c0;
  sin_cos(ws.q[kSwing], &s0, &c0);
  double* f0 = ws.f_parent[0].data();  // column-major: rotation about z, then the home's offset
  f0[0] = c0, f0[1] = s0, f0[2] = 0, f0[3] = 0, f0[4] = -s0, f0[5] = c0, f0[6] = 0, f0[7] = 0;
  f0[8] = 0, f0[9] = 0, f0[10] = 1, f0[11] = 0;
  f0[12] = m.home[0](0, 3), f0[13] = m.home[0](1, 3), f0[14] = m.home[0](2, 3), f0[15] = 1;
  ws.X_Wi[0] = ws.f_parent[0];
  ws.V[0] << 0, 0, w0, 0, 0, 0;
  std::array<double, kNumJoints>& y = ws.planar.origin_y;
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = kParent[i];
    y[i] = (p > 0 ? y[p] : 0.0) + m.home[i](1, 3);
    const double c = ws.cos_phi[i], s = ws.sin_phi[i];
    const Vec2& od = ws.origin_d[i];
    const double vx = od.x() - w0 * y[i];
    ws.V[i] << s * w0, -ws.omega[i], c * w0, c * vx + s * od.y(), w0 * ws.origin[i].x(), c * od.y() - s * vx;
    double* f = ws.f_parent[i].data();
    f[0] = ws.joint_cos[i], f[2] = ws.joint_sin[i], f[8] = -ws.joint_sin[i], f[10] = ws.joint_cos[i];
    f[12] = m.home[i](0, 3) + (kSlide[i] ? ws.q[i] : 0.0);
    f[13] = m.home[i](1, 3);
    f[14] = m.home[i](2, 3);
  }
  ws.pin_valid = true;
  ws.front_world_poses_valid = false;
}

// The tip T on the bucket: rho (z in the world), J_t, rhod, rhodd_bias, and T in the world.
void tip(const Model& m, Workspace& ws, const LoopRates& r, const Vec4& qd_a) {
  const Vec2 T = point_of(ws, kBucket, in_plane(m.tip_in_bucket));
  ws.rho = T + Vec2(0.0, m.machine.swing_height);
  // T moves with the boom's, the arm's and the bucket's pins, each driven by one cylinder.
  ws.J_t.col(0).setZero();
  ws.J_t.col(1) = perp(T - ws.origin[kBoom]) * r.psi[kBoom];
  ws.J_t.col(2) = perp(T - ws.origin[kArm]) * r.psi[kArm];
  ws.J_t.col(3) = perp(T - ws.origin[kBucket]) * r.psi[kBucket];
  ws.rhod.noalias() = ws.J_t.rightCols<3>() * qd_a.tail<3>();
  const Vec2 d = T - ws.origin[kBucket];
  const double w = ws.omega[kBucket];
  ws.rhodd_bias = ws.planar.acceleration[kBucket] + ws.planar.alpha[kBucket] * perp(d) - w * w * d;
  const double y = ws.planar.origin_y[kBucket] + m.tip_in_bucket.y();
  const SE3& X0 = ws.X_Wi[0];
  ws.tip_world = X0.topRightCorner<3, 1>() + Vec3(X0(0, 0) * T.x() + X0(0, 1) * y, X0(1, 0) * T.x() + X0(1, 1) * y, T.y());
}

// Each link's centre of mass and the Jacobians over q_a of its angle, origin and centre of mass
// (cylinder columns; the swing moves none of them in the plane), down the tree: a child's origin
// moves with its parent's origin and angle, plus its own slide. Once per update.
void link_jacobians(const Model& m, Workspace& ws) {
  Workspace::PlanarLinks& pl = ws.planar;
  if (pl.jacobians_valid) return;
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = kParent[i], n = kCylinder[i], k_own = kCylinder[i] - 1;
    const Vec2 d = perp(ws.origin[i] - ws.origin[p]);
    for (int k = 0; k < n; ++k) {
      pl.J_angle[i][k] = pl.J_angle[p][k];
      pl.J_origin[i].col(k) = pl.J_origin[p].col(k) + d * pl.J_angle[p][k];
    }
    if (kSlide[i]) pl.J_origin[i].col(k_own) += Vec2(ws.cos_phi[i], ws.sin_phi[i]);
    else pl.J_angle[i][k_own] += ws.Psi(i, k_own + 1);
    const BodyInertia& b = m.machine.bodies[i];
    const Vec2 rc = rotate(ws.cos_phi[i], ws.sin_phi[i], Vec2(b.com.x(), b.com.z()));
    pl.com[i] = ws.origin[i] + rc;
    pl.com_y[i] = pl.origin_y[i] + b.com.y();
    const Vec2 dc = perp(rc);
    for (int k = 0; k < n; ++k) pl.J_com[i].col(k) = pl.J_origin[i].col(k) + dc * pl.J_angle[i][k];
  }
  pl.jacobians_valid = true;
}

}  // namespace

bool has_planar_closed_chain_structure(const Model& model) {
  if (!model.planar_front) return false;
  for (int i = 0; i < kNumJoints; ++i)
    if (model.parent[i] != kParent[i] || model.prismatic[i] != kSlide[i]) return false;
  // Table 2: each loop's two links, the rods' ends at their origins and the links' ends on their x.
  const LoopCut* c = model.loops.data();
  return c[0].link_p == kBoom && c[0].link_s == kBoomRod && c[1].link_p == kArm && c[1].link_s == kArmRod &&
         c[2].link_p == kArm && c[2].link_s == kLink12 && c[3].link_p == kBucket && c[3].link_s == kLink11;
}

ModelReport planar_update_closed_chain(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                                       PassiveAngles angles) {
  // Position level: q_p from q_a in closed form (Table 2), with each pin's cos q, sin q.
  ws.report = solve_loop_closure(model, ws, q_a, angles);
  if (!ws.report.ok()) return ws.report;
  ws.loop_jacobian_valid = false;
  ws.planar.jacobians_valid = false;
  positions(model, ws);
  const LoopRates r = loop_rates(model, ws, qd_a);
  // A NaN or Inf anywhere makes the sum of magnitudes non-finite: one test instead of 16.
  double sum = 0;
  for (int i = 0; i < kNumJoints; ++i) sum += std::abs(r.psi[i]) + std::abs(r.gamma[i]);
  if (!std::isfinite(sum)) {
    ws.report = ModelReport{ModelStatus::singular, -1, 0};
    return ws.report;
  }
  ws.Psi.setZero();
  ws.Psi(kSwing, 0) = 1;
  ws.gamma.setZero();
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    ws.Psi(i, kCylinder[i]) = r.psi[i];
    ws.gamma[i] = r.gamma[i];
  }
  rates(ws, r);
  twists(model, ws);
  tip(model, ws, r, qd_a);
  return ws.report;
}

// M_a from the kinetic energy (eq. 17 in other words): a front link of mass m, centre of mass (X, Y, Z)
// in S and principal inertias Ixx, Iyy, Izz about its own axes has
//   T = 1/2 m ((Xd - w0 Y)^2 + w0^2 X^2 + Zd^2) + 1/2 Iyy phid^2 + 1/2 w0^2 (Ixx sin^2 phi + Izz cos^2 phi),
// so M_00 gets m (X^2 + Y^2) + Ixx sin^2 + Izz cos^2, M_0k gets -m Y dX/dq_k, and the cylinders' block
// m (dX dX^T + dZ dZ^T) + Iyy dphi dphi^T. The swing body adds its own inertia about the axis.
void planar_mass_matrix(const Model& model, Workspace& ws, Mat4& M_a) {
  link_jacobians(model, ws);
  const Workspace::PlanarLinks& pl = ws.planar;
  const BodyInertia& b0 = model.machine.bodies[0];
  M_a.setZero();
  M_a(0, 0) = b0.mass * (b0.com.x() * b0.com.x() + b0.com.y() * b0.com.y()) + b0.inertia.z();
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    const int n = kCylinder[i];
    const BodyInertia& b = model.machine.bodies[i];
    const double m = b.mass, X = pl.com[i].x(), Y = pl.com_y[i], s = ws.sin_phi[i], c = ws.cos_phi[i];
    const Eigen::Matrix<double, 2, 3>& J = pl.J_com[i];
    const Vec3& Ja = pl.J_angle[i];
    M_a(0, 0) += m * (X * X + Y * Y) + b.inertia.x() * s * s + b.inertia.z() * c * c;
    for (int k = 0; k < n; ++k) {
      M_a(0, 1 + k) -= m * Y * J(0, k);
      for (int l = k; l < n; ++l) M_a(1 + k, 1 + l) += m * J.col(k).dot(J.col(l)) + b.inertia.y() * Ja[k] * Ja[l];
    }
  }
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) M_a(l, k) = M_a(k, l);
}

// h_a by Kane's equations at qdd_a = 0: each link's inertia force and moment at the accelerations
// gamma gives, dotted with its partial velocities, plus gravity. In the frame S turning at w0 about z
// (w0d = 0 here), the centre of mass accelerates at (Xdd - w0^2 X, 2 w0 Xd - w0^2 Y, Zdd) with
// (Xdd, Zdd) its acceleration in the plane; the link turns at (0, -phid, w0) and its inertia in S has
// Ixz = cos sin (Ixx - Izz), so I alpha + w x I w = (.., -Iyy phidd + Ixz w0^2, 2 Ixz w0 phid). The
// partial velocities are (-Y, X, 0) and (0, 0, 1) for the swing, (dX, 0, dZ) and (0, -dphi, 0) for a
// cylinder. The swing body turns about its own axis and adds nothing.
void planar_bias_forces(const Model& model, Workspace& ws, Vec4& h_a) {
  link_jacobians(model, ws);
  const Workspace::PlanarLinks& pl = ws.planar;
  const double w0 = ws.qd[kSwing], g = model.machine.gravity;
  const double qd_cylinders[3] = {ws.qd[kBoomRod], ws.qd[kArmRod], ws.qd[kBucketRod]};
  h_a.setZero();
#pragma GCC unroll 12
  for (int i = 1; i < kNumJoints; ++i) {
    const int n = kCylinder[i];
    const BodyInertia& b = model.machine.bodies[i];
    const double m = b.mass, X = pl.com[i].x(), Y = pl.com_y[i], s = ws.sin_phi[i], c = ws.cos_phi[i];
    const Eigen::Matrix<double, 2, 3>& J = pl.J_com[i];
    const Vec3& Ja = pl.J_angle[i];
    double Xd = 0;
    for (int k = 0; k < n; ++k) Xd += J(0, k) * qd_cylinders[k];
    const Vec2 rc = pl.com[i] - ws.origin[i];
    const double w = ws.omega[i], a = pl.alpha[i];
    const Vec2 acc = pl.acceleration[i] + a * perp(rc) - w * w * rc;  // the com's, in the plane
    const double Ixz = c * s * (b.inertia.x() - b.inertia.z());
    h_a[0] += m * (2 * w0 * X * Xd - Y * acc.x()) + 2 * Ixz * w0 * w;
    const double fx = m * (acc.x() - w0 * w0 * X), fz = m * (acc.y() + g), moment = b.inertia.y() * a - Ixz * w0 * w0;
    for (int k = 0; k < n; ++k) h_a[1 + k] += J(0, k) * fx + J(1, k) * fz + Ja[k] * moment;
  }
}

}  // namespace exc
