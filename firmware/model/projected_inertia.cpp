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

// The cylinder columns of a front link i with parent columns Jp: Ad_{f^-1} Jp plus the joint's own
// term (row: w_y for a pin, v_x for a slide). Only the first N can be nonzero (the parent's beyond
// N are zero and so is Psi(i, k) there): the rest are zeroed, not computed.
template <int N>
void front_columns(double c, double s, const Vec3& offset, int row, double sign, const Mat12x4& Psi, int i,
                   const Mat3& Jp, Mat3& J) {
  for (int k = 0; k < N; ++k) {
    J.col(k) = Ad_inv_in_plane(c, s, offset, Jp.col(k));
    J(row, k) += sign * Psi(i, k + 1);
  }
  for (int k = N; k < 3; ++k) J.col(k).setZero();
}

// The link's share of M_a from its first N cylinder columns J: J^T G J on the upper triangle, with
// G's in-plane block [[a, b, c], [b, m, 0], [c, 0, m]] (spatial_inertia), and the swing column's
// cross terms (G J_0 on the plane) . J.
template <int N>
void add_in_plane(const Mat3& G, const Mat3& J, const Vec3& GJ0_in, Mat4& M_a) {
  const double a = G(0, 0), b = G(0, 1), cz = G(0, 2), m = G(1, 1);
  Mat3 GJ;
  for (int k = 0; k < N; ++k) {
    GJ(0, k) = a * J(0, k) + b * J(1, k) + cz * J(2, k);
    GJ(1, k) = b * J(0, k) + m * J(1, k);
    GJ(2, k) = cz * J(0, k) + m * J(2, k);
  }
  for (int k = 0; k < N; ++k) {
    M_a(0, 1 + k) += GJ0_in.dot(J.col(k));
    for (int l = k; l < N; ++l) M_a(1 + k, 1 + l) += J.col(k).dot(GJ.col(l));
  }
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
  std::array<Mat3, kNumJoints> Jf;  // columns: cylinder k, rows: (w_y, v_x, v_z)
  // Only the first n[i] cylinder columns of link i can be nonzero: a cylinder moves the links of its
  // loop and their subtrees (in q_a's boom, arm, bucket order: 1 on the boom's links, 2 on the arm's,
  // 3 on the bucket's), so the others are neither transformed nor multiplied.
  std::array<int, kNumJoints> n;
  M_a.setZero();
  for (int i = 0; i < kNumJoints; ++i) {
    const int p = model.parent[i];
    if (p < 0) {
      J0[i] = model.screw[i] * Psi(i, 0);
      n[i] = 0;
      for (int k = 1; k < kNumActive; ++k) {
        const Twist t = model.screw[i] * Psi(i, k);
        Jf[i].col(k - 1) << t[1], t[3], t[5];
        if (!Jf[i].col(k - 1).isZero(0.0)) n[i] = k;
      }
    } else {
      const double c = ws.joint_cos[i], s = ws.joint_sin[i];
      const Vec3 offset = ws.f_parent[i].topRightCorner<3, 1>();
      J0[i] = Ad_inv_apply_pin(c, s, offset, J0[p]);
      const int row = model.prismatic[i] ? 1 : 0;
      const double sign = model.prismatic[i] ? 1.0 : -1.0;
      J0[i][model.prismatic[i] ? 3 : 1] += sign * Psi(i, 0);
      n[i] = n[p];
      for (int k = n[p] + 1; k < kNumActive; ++k)
        if (Psi(i, k) != 0.0) n[i] = k;
      switch (n[i]) {
        case 0: Jf[i].setZero(); break;
        case 1: front_columns<1>(c, s, offset, row, sign, Psi, i, Jf[p], Jf[i]); break;
        case 2: front_columns<2>(c, s, offset, row, sign, Psi, i, Jf[p], Jf[i]); break;
        default: front_columns<3>(c, s, offset, row, sign, Psi, i, Jf[p], Jf[i]); break;
      }
    }
    const BodyInertia& body = model.machine.bodies[i];
    const Wrench GJ0 = inertia_apply(body.mass, body.com, body.inertia, J0[i]);
    M_a(0, 0) += J0[i].dot(GJ0);
    const Vec3 GJ0_in(GJ0[1], GJ0[3], GJ0[5]);
    const Mat3& G = model.inertia_in_plane[i];
    switch (n[i]) {
      case 0: break;
      case 1: add_in_plane<1>(G, Jf[i], GJ0_in, M_a); break;
      case 2: add_in_plane<2>(G, Jf[i], GJ0_in, M_a); break;
      default: add_in_plane<3>(G, Jf[i], GJ0_in, M_a); break;
    }
  }
  for (int k = 0; k < 4; ++k)
    for (int l = k + 1; l < 4; ++l) M_a(l, k) = M_a(k, l);
}

}  // namespace exc
