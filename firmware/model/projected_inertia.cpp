// M_a as a sum of body kinetic energies (see projected_inertia.hpp).
#include "projected_inertia.hpp"

#include "lie_group.hpp"
#include "newton_euler.hpp"

namespace exc {

namespace {

// Ad_{f^-1} on an in-plane twist j for f = (pin rotation about -y by cos c, sin s; offset p): the
// general map with w_x = w_z = v_y = 0, which keeps them zero.
inline Vec3 Ad_inv_in_plane(double c, double s, const Vec3& p, const Vec3& j) {
  const double a = j[1] + p.z() * j[0], b = j[2] - p.x() * j[0];
  return Vec3(j[0], c * a + s * b, c * b - s * a);
}

}  // namespace

void projected_mass_matrix(const Model& model, const Workspace& ws, const Mat12x4& Psi, Mat4& M_a) {
  if (!ws.pin_valid) {
    Mat12x4 MPsi;
    tree_inertia_times<4>(model, ws, Psi, MPsi);
    M_a.noalias() = Psi.transpose().lazyProduct(MPsi);
    M_a = (0.5 * (M_a + M_a.transpose())).eval();
    return;
  }
  // Column 0 (swing) as full twists; columns 1-3 (the cylinders) as in-plane triples. The front's
  // screws are known: a pin adds -Psi to w_y, a slide +Psi to v_x.
  std::array<Twist, kNumJoints> J0;
  std::array<Eigen::Matrix3d, kNumJoints> Jf;  // columns: cylinder k, rows: (w_y, v_x, v_z)
  M_a.setZero();
  for (int i = 0; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    if (p < 0) {
      J0[i] = model.screw[i] * Psi(i, 0);
      Jf[i] = Eigen::Matrix3d::Zero();
      for (int k = 1; k < kNumActive; ++k) {
        const Twist t = model.screw[i] * Psi(i, k);
        Jf[i].col(k - 1) << t[1], t[3], t[5];
      }
    } else {
      const double c = ws.joint_cos[i], s = ws.joint_sin[i];
      const Vec3 offset = ws.f_parent[i].topRightCorner<3, 1>();
      J0[i] = Ad_inv_apply_pin(c, s, offset, J0[p]);
      const int row = model.prismatic[i] ? 1 : 0;
      const double sign = model.prismatic[i] ? 1.0 : -1.0;
      J0[i][model.prismatic[i] ? 3 : 1] += sign * Psi(i, 0);
      for (int k = 1; k < kNumActive; ++k) {
        Jf[i].col(k - 1) = Ad_inv_in_plane(c, s, offset, Jf[p].col(k - 1));
        Jf[i](row, k - 1) += sign * Psi(i, k);
      }
    }
    // J^T G J: the in-plane block of G for the cylinder columns; the swing column in full. The
    // in-plane block of a spatial inertia about the origin is [[a, b, c], [b, m, 0], [c, 0, m]]
    // (spatial_inertia), and J^T G J is symmetric: its upper triangle only.
    const Mat3& G = model.inertia_in_plane[i];
    const double a = G(0, 0), b = G(0, 1), cz = G(0, 2), m = G(1, 1);
    const Mat3& J = Jf[i];
    Mat3 GJ;
    for (int k = 0; k < 3; ++k) {
      GJ(0, k) = a * J(0, k) + b * J(1, k) + cz * J(2, k);
      GJ(1, k) = b * J(0, k) + m * J(1, k);
      GJ(2, k) = cz * J(0, k) + m * J(2, k);
    }
    for (int k = 0; k < 3; ++k)
      for (int l = k; l < 3; ++l) M_a(1 + k, 1 + l) += J.col(k).dot(GJ.col(l));
    const BodyInertia& body = model.machine.bodies[i];
    const Wrench GJ0 = inertia_apply(body.mass, body.com, body.inertia, J0[i]);
    M_a(0, 0) += J0[i].dot(GJ0);
    const Vec3 GJ0_in(GJ0[1], GJ0[3], GJ0[5]);
    M_a.block<1, 3>(0, 1).noalias() += GJ0_in.transpose().lazyProduct(J);
  }
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) M_a(l, k) = M_a(k, l);
}

}  // namespace exc
