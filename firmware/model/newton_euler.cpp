// Newton-Euler for the tree (paper eq. 1 with model.md's corrections: the second forward line is the
// acceleration, and the backward sum transforms each child's wrench with f_{i,k} of that child).
#include "newton_euler.hpp"

#include "lie_group.hpp"
#include "sin_cos.hpp"

namespace exc {

void tree_kinematics(const Model& model, Workspace& ws, const Vec12& q, const Vec12& qd) {
  ws.q = q;
  ws.qd = qd;
  ws.pin_valid = false;
  ws.front_world_poses_valid = true;
  for (int i = 0; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    // eq. 1: f = M exp([S] q), with the closed form for a revolute or prismatic screw.
    if (model.home_is_translation[i]) {
      ws.f_parent[i] = joint_motion(model.screw[i], q[i], model.prismatic[i]);
      ws.f_parent[i].topRightCorner<3, 1>() += model.home[i].topRightCorner<3, 1>();
    } else {
      ws.f_parent[i] = compose(model.home[i], joint_motion(model.screw[i], q[i], model.prismatic[i]));
    }
    const Twist S_qd = model.screw[i] * qd[i];
    if (p < 0) {
      ws.X_Wi[i] = ws.f_parent[i];
      ws.V[i] = S_qd;  // the base does not move
    } else {
      ws.X_Wi[i] = compose(ws.X_Wi[p], ws.f_parent[i]);
      ws.V[i] = Ad_inv_apply(ws.f_parent[i], ws.V[p]) + S_qd;  // eq. 1, velocity
    }
  }
  ws.tip_world = ws.X_Wi[kBucket].topLeftCorner<3, 3>() * model.tip_in_bucket +
                 ws.X_Wi[kBucket].topRightCorner<3, 1>();
}

namespace {

// Homogeneous transforms written by columns (column-major storage), without temporaries: these run
// 24 times per update.
inline void set_pose(SE3& T, const Vec3& x, const Vec3& y, const Vec3& z, const Vec3& p) {
  double* d = T.data();
  d[0] = x.x(), d[1] = x.y(), d[2] = x.z(), d[3] = 0;
  d[4] = y.x(), d[5] = y.y(), d[6] = y.z(), d[7] = 0;
  d[8] = z.x(), d[9] = z.y(), d[10] = z.z(), d[11] = 0;
  d[12] = p.x(), d[13] = p.y(), d[14] = p.z(), d[15] = 1;
}


// Out-of-plane offset of each front origin (pin rotations and slides keep it): the homes' y summed
// along its path. From the Model's homes on every call (11 additions), not stored: a Model's homes
// may be edited after build_model (a test shifts one out of the plane).
std::array<double, kNumJoints> front_y_offsets(const Model& model) {
  std::array<double, kNumJoints> y{};
  for (int i = 1; i < kNumJoints; ++i) y[i] = (model.parent[i] > 0 ? y[model.parent[i]] : 0.0) + model.home[i](1, 3);
  return y;
}

// World pose of front link i: swing about z, then the link's absolute angle about -y; origin from
// the planar pass.
void set_front_world_pose(const Workspace& ws, int i, double y, SE3& X) {
  const SE3& X0 = ws.X_Wi[0];
  const double c0 = X0(0, 0), s0 = X0(1, 0);
  const double ca = ws.cos_phi[i], sa = ws.sin_phi[i];
  const Vec2& o = ws.origin[i];
  set_pose(X, Vec3(c0 * ca, s0 * ca, sa), Vec3(-s0, c0, 0), Vec3(-c0 * sa, -s0 * sa, ca),
           X0.topRightCorner<3, 1>() + Vec3(c0 * o.x() - s0 * y, s0 * o.x() + c0 * y, o.y()));
}

// Ad_{f^-1} X into link i from its parent, and Ad*_{f^-1} F from link i to its parent: by the pin
// transforms when they are current (pin: ws.pin_valid, read once by the caller, since the passes
// write into ws and the compiler would read it again per link), else by the general f_parent.
EXC_HOT_INLINE Twist to_child(bool pin, const Workspace& ws, int i, const Twist& X) {
  return pin ? Ad_inv_apply_pin(ws.joint_cos[i], ws.joint_sin[i], ws.f_parent[i].topRightCorner<3, 1>(), X)
             : Ad_inv_apply(ws.f_parent[i], X);
}
EXC_HOT_INLINE Wrench to_parent(bool pin, const Workspace& ws, int i, const Wrench& F) {
  return pin ? Ad_inv_dual_apply_pin(ws.joint_cos[i], ws.joint_sin[i], ws.f_parent[i].topRightCorner<3, 1>(), F)
             : Ad_inv_dual_apply(ws.f_parent[i], F);
}

}  // namespace

void tree_kinematics_from_front(const Model& model, Workspace& ws, const Vec12& qd) {
  if (!model.planar_front) {
    tree_kinematics(model, ws, Vec12(ws.q), qd);
    return;
  }
  ws.qd = qd;
  double s0, c0;  // the swing's sin, cos (about z)
  sin_cos(ws.q[0], &s0, &c0);
  set_pose(ws.f_parent[0], Vec3(c0, s0, 0), Vec3(-s0, c0, 0), Vec3::UnitZ(), model.home[0].topRightCorner<3, 1>());
  ws.X_Wi[0] = ws.f_parent[0];
  ws.V[0] = model.screw[0] * qd[0];
  for (int i = 1; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    // Relative motion: a pin rotation about -y by q_i (cos, sin from the front pass) or a slide (cos
    // 1, sin 0). Only the rotation's cos, sin and the offset are written: f_parent's other entries
    // are those of every front joint (0 and 1, set from the home translations by the Workspace and
    // by tree_kinematics).
    const double c = ws.joint_cos[i], s = ws.joint_sin[i];
    double* f = ws.f_parent[i].data();  // column-major
    f[0] = c, f[2] = s, f[8] = -s, f[10] = c;
    f[12] = model.home[i](0, 3) + (model.prismatic[i] ? ws.q[i] : 0.0);
    f[13] = model.home[i](1, 3);
    f[14] = model.home[i](2, 3);
    ws.V[i] = Ad_inv_apply_pin(c, s, ws.f_parent[i].topRightCorner<3, 1>(), ws.V[p]);
    ws.V[i][model.prismatic[i] ? 3 : 1] += model.prismatic[i] ? qd[i] : -qd[i];  // + S_i qd_i
  }
  ws.pin_valid = true;
  ws.front_world_poses_valid = false;
  SE3 X_bucket;
  set_front_world_pose(ws, kBucket, front_y_offsets(model)[kBucket], X_bucket);
  ws.tip_world = X_bucket.topLeftCorner<3, 3>() * model.tip_in_bucket + X_bucket.topRightCorner<3, 1>();
}

void tree_world_poses(const Model& model, Workspace& ws) {
  if (ws.front_world_poses_valid) return;
  const std::array<double, kNumJoints> y = front_y_offsets(model);
  for (int i = 1; i < kNumJoints; ++i) set_front_world_pose(ws, i, y[i], ws.X_Wi[i]);
  ws.front_world_poses_valid = true;
}

void tree_inverse_dynamics(const Model& model, Workspace& ws, const Vec12& qdd, const Vec2& f_soil,
                           Vec12& tau) {
  // Forward: accelerations, with gravity as the base acceleration Vd_0 (model.md s.3).
  const bool pin = ws.pin_valid;  // read once: the passes below branch on it per link
  for (int i = 0; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    const Twist& V = ws.V[i];
    Twist& Vd = ws.Vd[i];
    if (pin && i > 0) {
      // The front's screws are known (build_model checked them): a pin S = (-e_y, 0) or a slide
      // S = (0, e_x), so S qdd and ad_V (S qd) are a few products.
      Vd = Ad_inv_apply_pin(ws.joint_cos[i], ws.joint_sin[i], ws.f_parent[i].topRightCorner<3, 1>(), ws.Vd[p]);
      const double rate = ws.qd[i];
      if (model.prismatic[i]) {
        Vd[3] += qdd[i];
        Vd[4] += rate * V[2];
        Vd[5] -= rate * V[1];
      } else {
        Vd[1] -= qdd[i];
        Vd[0] += rate * V[2];
        Vd[2] -= rate * V[0];
        Vd[3] += rate * V[5];
        Vd[5] -= rate * V[3];
      }
    } else {
      const Twist S_qd = model.screw[i] * ws.qd[i];
      const Twist Vd_parent = p < 0 ? model.base_acceleration : Twist(ws.Vd[p]);
      // eq. 1 (corrected): Vd_i = Ad_{f^-1} Vd_p - ad_{S qd} Ad_{f^-1} V_p + S qdd; ad_{V_i} S qd is
      // the same term since ad_{S qd} S qd = 0.
      Vd = Ad_inv_apply(ws.f_parent[i], Vd_parent) + ad_apply(V, S_qd) + model.screw[i] * qdd[i];
    }
    const BodyInertia& b = model.machine.bodies[i];
    const Wrench momentum = inertia_apply(b.mass, b.com, b.inertia, V);
    ws.F[i] = inertia_apply(b.mass, b.com, b.inertia, Vd) - ad_dual_apply(V, momentum);
  }
  // The soil pushes on the bucket with -f_soil at the tip T: the joints must supply +f_soil there
  // (paper eq. 2). f_soil is in the swing plane of the swing frame.
  if (f_soil.x() != 0.0 || f_soil.y() != 0.0) {
    Vec3 f_b;  // in the bucket frame
    if (pin) {
      // The bucket is turned from the swing frame about -y by its absolute angle in the plane.
      const double c = ws.cos_phi[kBucket], s = ws.sin_phi[kBucket];
      f_b << c * f_soil.x() + s * f_soil.y(), 0.0, c * f_soil.y() - s * f_soil.x();
    } else {
      const Mat3 R_sw_bucket = ws.X_Wi[kSwing].topLeftCorner<3, 3>().transpose() *
                               ws.X_Wi[kBucket].topLeftCorner<3, 3>();
      f_b = R_sw_bucket.transpose() * Vec3(f_soil.x(), 0.0, f_soil.y());
    }
    ws.F[kBucket].head<3>() += model.tip_in_bucket.cross(f_b);
    ws.F[kBucket].tail<3>() += f_b;
  }
  // Backward: children have higher indices than their parents (Table 1 order). eq. 1: tau_i =
  // S_i^T F_i; for the front's known screws (pin) one entry of F_i.
  for (int i = kNumJoints - 1; i >= 0; --i) {
    const int p = model.parent[i];
    tau[i] = pin && p >= 0 ? (model.prismatic[i] ? ws.F[i][3] : -ws.F[i][1]) : model.screw[i].dot(ws.F[i]);
    if (p >= 0) ws.F[p] += to_parent(pin, ws, i, ws.F[i]);
  }
  ws.tau_r = tau;
}

template <int N>
void tree_inertia_times(const Model& model, const Workspace& ws, const Eigen::Matrix<double, 12, N>& A,
                        Eigen::Matrix<double, 12, N>& out) {
  // The passes of tree_inverse_dynamics with V = 0 and no gravity, one acceleration column at a
  // time, with the same transform and inertia products.
  std::array<Twist, kNumJoints> acc;
  std::array<Wrench, kNumJoints> force;
  const bool pin = ws.pin_valid;
  for (int col = 0; col < N; ++col) {
    for (int i = 0; i < kNumJoints; ++i) {
      const int p = model.parent[i];
      acc[i] = model.screw[i] * A(i, col);
      if (p >= 0) acc[i] += to_child(pin, ws, i, acc[p]);
      const BodyInertia& b = model.machine.bodies[i];
      force[i] = inertia_apply(b.mass, b.com, b.inertia, acc[i]);
    }
    for (int i = kNumJoints - 1; i >= 0; --i) {
      out(i, col) = model.screw[i].dot(force[i]);
      const int p = model.parent[i];
      if (p < 0) continue;
      force[p] += to_parent(pin, ws, i, force[i]);
    }
  }
}

template void tree_inertia_times<4>(const Model&, const Workspace&, const Eigen::Matrix<double, 12, 4>&,
                                    Eigen::Matrix<double, 12, 4>&);
template void tree_inertia_times<12>(const Model&, const Workspace&, const Eigen::Matrix<double, 12, 12>&,
                                     Eigen::Matrix<double, 12, 12>&);

void tree_mass_matrix(const Model& model, const Workspace& ws, Mat12& M_r) {
  tree_inertia_times<12>(model, ws, Mat12::Identity(), M_r);
  M_r = (0.5 * (M_r + M_r.transpose())).eval();  // exact in theory; remove rounding asymmetry
}

}  // namespace exc
