// The closed chain in independent coordinates (paper eqs. 3-7, 14-17; model.md s.4).
#include "closed_chain.hpp"

#include <cmath>

#include <Eigen/LU>

#include "front_kinematics.hpp"
#include "lie_group.hpp"
#include "loop_closure.hpp"
#include "newton_euler.hpp"
#include "planar_closed_chain.hpp"
#include "projected_inertia.hpp"

namespace exc {

namespace {
// The soil and gravity are the only external loads; for M_a and h_a the soil is left out.
const Vec2 kNoSoil = Vec2::Zero();

// B A for B = H_p^-1 (or its transpose), block diagonal by loops (2, 2, 4): a third of the products of
// the full 8 x 8 one.
template <typename Block8, typename In, typename Out>
void times_block_diagonal(const Block8& B, const In& A, Out& out) {
  out.template topRows<2>().noalias() = B.template block<2, 2>(0, 0).lazyProduct(A.template topRows<2>());
  out.template middleRows<2>(2).noalias() = B.template block<2, 2>(2, 2).lazyProduct(A.template middleRows<2>(2));
  out.template bottomRows<4>().noalias() = B.template block<4, 4>(4, 4).lazyProduct(A.template bottomRows<4>());
}

// H = dh/dq (eq. 4) at the positions in ws and H_p^-1 by its blocks; returns H_a.
Mat8x4 form_loop_jacobian(const Model& model, Workspace& ws) {
  front_loop_jacobian(model, ws, ws.H);
  // At closure H_p is block diagonal (boom loop, arm loop, bucket four-bar), so it is inverted by
  // blocks; the closed form has already reported a singular block (no assembly or toggle).
  Mat8 H_p;
  Mat8x4 H_a;
  for (int k = 0; k < kNumPassive; ++k) H_p.col(k) = ws.H.col(kPassiveJoints[k]);
  for (int k = 0; k < kNumActive; ++k) H_a.col(k) = ws.H.col(kActiveJoints[k]);
  ws.Hp_inv.setZero();
  ws.Hp_inv.block<2, 2>(0, 0) = H_p.block<2, 2>(0, 0).inverse();
  ws.Hp_inv.block<2, 2>(2, 2) = H_p.block<2, 2>(2, 2).inverse();
  ws.Hp_inv.block<4, 4>(4, 4) = H_p.block<4, 4>(4, 4).inverse();
  ws.loop_jacobian_valid = true;
  return H_a;
}

// The general path: the loop Jacobian, Psi and gamma from it, the tree passes (model.md s.4).
ModelReport general_update_closed_chain(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                                        PassiveAngles angles) {
  // Position level: q_p from q_a in closed form (Table 2), with each pin's cos q, sin q.
  ws.report = solve_loop_closure(model, ws, q_a, angles);
  if (!ws.report.ok()) return ws.report;
  front_positions_from_joint_trig(model, ws.q, ws);

  // Velocity level: qd = Psi qd_a, Psi = [I; -H_p^-1 H_a] (eq. 16a), in tree order.
  const Mat8x4 H_a = form_loop_jacobian(model, ws);
  Mat8x4 dqp_dqa;
  Vec8 gamma_p;
  times_block_diagonal(ws.Hp_inv, H_a, dqp_dqa);  // H_p^-1 H_a; Psi takes its negative
  ws.Psi.setZero();
  for (int k = 0; k < kNumActive; ++k) {
    ws.Psi(kActiveJoints[k], k) = 1.0;
    ws.qd[kActiveJoints[k]] = qd_a[k];
  }
  Vec8 qd_p;  // Psi's passive rows times qd_a, without its unit and zero rows
  qd_p.noalias() = dqp_dqa.lazyProduct(qd_a);
  for (int k = 0; k < kNumPassive; ++k) {
    ws.Psi.row(kPassiveJoints[k]) = -dqp_dqa.row(k);
    ws.qd[kPassiveJoints[k]] = -qd_p[k];
  }

  // Acceleration bias: with qdd = 0 the cut pins accelerate apart by Hd qd; gamma = (0; -H_p^-1 Hd qd).
  front_rates(model, ws.qd, Vec12::Zero(), ws);
  front_loop_acceleration(model, ws, ws.Hd_qd);
  times_block_diagonal(ws.Hp_inv, ws.Hd_qd, gamma_p);
  ws.gamma.setZero();
  for (int k = 0; k < kNumPassive; ++k) ws.gamma[kPassiveJoints[k]] = -gamma_p[k];
  // A NaN or Inf anywhere makes the sum of magnitudes non-finite: one test instead of 40 (Psi's
  // and gamma's other entries are 0 and 1).
  if (!std::isfinite(dqp_dqa.cwiseAbs().sum() + gamma_p.cwiseAbs().sum())) {
    ws.report = ModelReport{ModelStatus::singular, -1, 0};
    return ws.report;
  }

  // Tip kinematics (eq. 2): rho in the swing plane, z measured in the world.
  Vec2 tip;
  front_tip(model, ws, tip, ws.J_tip_tree, ws.tip_acc_tree);
  ws.rho = tip + Vec2(0.0, model.machine.swing_height);
  // J_tip_tree is zero off the bucket's path to the swing: J_t and the bias from its columns only.
  ws.J_t.setZero();
  ws.rhodd_bias = ws.tip_acc_tree;
  for (int j = kBucket; j > 0; j = model.parent[j]) {
    ws.J_t.noalias() += ws.J_tip_tree.col(j) * ws.Psi.row(j);
    ws.rhodd_bias += ws.J_tip_tree.col(j) * ws.gamma[j];
  }
  ws.rhod.noalias() = ws.J_t.lazyProduct(qd_a);

  // Tree poses and twists for Newton-Euler (also fills ws.tip_world), from the planar pass above.
  tree_kinematics_from_front(model, ws, ws.qd);
  return ws.report;
}

}  // namespace

void ensure_loop_jacobian(const Model& model, Workspace& ws) {
  if (!ws.loop_jacobian_valid) form_loop_jacobian(model, ws);
}

ModelReport update_closed_chain(const Model& model, Workspace& ws, const Vec4& q_a, const Vec4& qd_a,
                                PassiveAngles angles) {
  if (!q_a.allFinite() || !qd_a.allFinite()) {
    ws.report = ModelReport{ModelStatus::non_finite_input, -1, 0};
    return ws.report;
  }
  ws.loop_jacobian_valid = false;
  ws.planar.jacobians_valid = false;
  return model.closed_chain_path == ClosedChainPath::planar ? planar_update_closed_chain(model, ws, q_a, qd_a, angles)
                                                            : general_update_closed_chain(model, ws, q_a, qd_a, angles);
}

void inverse_dynamics(const Model& model, Workspace& ws, const Vec4& qdd_a, const Vec2& f_soil, Vec4& tau_a) {
  ws.qdd.noalias() = ws.Psi.lazyProduct(qdd_a);  // eq. 16a, differentiated
  ws.qdd += ws.gamma;
  tree_inverse_dynamics(model, ws, ws.qdd, f_soil, ws.tau_r);
  tau_a.noalias() = ws.Psi.transpose().lazyProduct(ws.tau_r);  // eq. 16b
  // eq. 7a: tau_r = tau_act + H^T F_c with tau_act zero on the passive joints, so H_p^T F_c = tau_p.
  ensure_loop_jacobian(model, ws);
  Vec8 tau_p;
  for (int k = 0; k < kNumPassive; ++k) tau_p[k] = ws.tau_r[kPassiveJoints[k]];
  times_block_diagonal(ws.Hp_inv.transpose(), tau_p, ws.F_c);
}

void mass_matrix(const Model& model, Workspace& ws, Mat4& M_a) {
  if (model.closed_chain_path == ClosedChainPath::planar) return planar_mass_matrix(model, ws, M_a);
  projected_mass_matrix(model, ws, ws.Psi, M_a);  // eq. 17
}

void bias_forces(const Model& model, Workspace& ws, Vec4& h_a) {
  if (model.closed_chain_path == ClosedChainPath::planar) return planar_bias_forces(model, ws, h_a);
  Vec12 tau;
  tree_inverse_dynamics(model, ws, ws.gamma, kNoSoil, tau);  // C_r qd + g_r + M_r gamma
  h_a.noalias() = ws.Psi.transpose().lazyProduct(tau);
}

}  // namespace exc
