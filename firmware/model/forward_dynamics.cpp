// Forward dynamics in independent coordinates (model.md s.4) and in the augmented form (eq. 8).
#include "forward_dynamics.hpp"

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/LU>

#include "front_kinematics.hpp"
#include "newton_euler.hpp"

namespace exc {

ModelReport forward_dynamics(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                             const Vec4& tau_a, const TipLoad& load, Vec4& qdd_a) {
  if (!tau_a.allFinite() || !load.force.allFinite() || !load.added_mass.allFinite())
    return ws.report = ModelReport{ModelStatus::non_finite_input, -1, 0};
  const ModelReport r = update_closed_chain(model, ws, q_a, qd_a);
  if (!r.ok()) return r;
  Mat4 M_a;
  Vec4 h_a;
  mass_matrix(model, ws, M_a);
  bias_forces(model, ws, h_a);
  // The soil's added mass moves with the tip: F_soil = f + M_t (J_t qdd_a + rhodd_bias) (eq. 9).
  const Mat2 M_t = load.added_mass.asDiagonal();
  const Mat4 A = M_a + ws.J_t.transpose() * M_t * ws.J_t;
  const Vec4 b = tau_a - h_a - ws.J_t.transpose() * (load.force + M_t * ws.rhodd_bias);
  const Eigen::LLT<Mat4> llt(A);
  if (llt.info() != Eigen::Success) return ws.report = ModelReport{ModelStatus::singular, -1, r.conditioning};
  const Vec4 x = llt.solve(b);
  if (!x.allFinite()) return ws.report = ModelReport{ModelStatus::singular, -1, r.conditioning};
  qdd_a = x;
  return r;
}

ModelReport forward_dynamics_augmented(const Model& model, Workspace& ws, const Vec12& q, const Vec12& qd,
                                       const Vec4& tau_a, const TipLoad& load, double baumgarte_alpha,
                                       double baumgarte_beta, Vec12& qdd, Vec8& lambda) {
  if (!q.allFinite() || !qd.allFinite() || !tau_a.allFinite() || !load.force.allFinite() ||
      !load.added_mass.allFinite() || !std::isfinite(baumgarte_alpha) || !std::isfinite(baumgarte_beta))
    return ws.report = ModelReport{ModelStatus::non_finite_input, -1, 0};

  // Planar front: h, H, Hd qd and the tip at these (possibly drifted) coordinates.
  Vec8 h;
  front_positions(model, q, ws);
  front_loop_residual(model, ws, h);
  front_loop_jacobian(model, ws, ws.H);
  front_rates(model, qd, Vec12::Zero(), ws);
  front_loop_acceleration(model, ws, ws.Hd_qd);
  Vec2 tip;
  front_tip(model, ws, tip, ws.J_tip_tree, ws.tip_acc_tree);

  // C qd + g + J^T f at qdd = 0, with the soil's added-mass term moved to the left-hand side.
  ws.q = q;
  tree_kinematics_from_front(model, ws, qd);
  const Mat2 M_t = load.added_mass.asDiagonal();
  const Vec2 f_known = load.force + M_t * ws.tip_acc_tree;
  Vec12 bias;
  tree_inverse_dynamics(model, ws, Vec12::Zero(), f_known, bias);
  tree_mass_matrix(model, ws, ws.M_r);

  // eq. 8: [M_r H^T; H 0] [qdd; -lambda] = [tau - C qd - g - J^T f; -Hd qd - 2 alpha hd - beta^2 h].
  using Mat20 = Eigen::Matrix<double, 20, 20>;
  using Vec20 = Eigen::Matrix<double, 20, 1>;
  Mat20 K = Mat20::Zero();
  K.topLeftCorner<12, 12>() = ws.M_r + ws.J_tip_tree.transpose() * M_t * ws.J_tip_tree;
  K.topRightCorner<12, 8>() = ws.H.transpose();
  K.bottomLeftCorner<8, 12>() = ws.H;
  Vec20 rhs;
  Vec12 tau = Vec12::Zero();
  for (int k = 0; k < kNumActive; ++k) tau[kActiveJoints[k]] = tau_a[k];
  rhs.head<12>() = tau - bias;
  const Vec8 hd = ws.H * qd;
  rhs.tail<8>() = -ws.Hd_qd - 2.0 * baumgarte_alpha * hd - baumgarte_beta * baumgarte_beta * h;
  const Eigen::PartialPivLU<Mat20> lu(K);
  const double rcond = lu.rcond();
  if (!(rcond > 1e-14)) return ws.report = ModelReport{ModelStatus::singular, -1, rcond};
  const Vec20 x = lu.solve(rhs);
  if (!x.allFinite()) return ws.report = ModelReport{ModelStatus::singular, -1, rcond};
  qdd = x.head<12>();
  lambda = -x.tail<8>();
  ws.qdd = qdd;
  ws.report = ModelReport{ModelStatus::ok, -1, rcond};
  return ws.report;
}

}  // namespace exc
