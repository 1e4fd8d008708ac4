#pragma once
// Every buffer the algorithms write (Pinocchio's Data): built once from a Model, reused each step.
// All members are fixed-size; after construction nothing allocates.
#include <Eigen/LU>

#include "model.hpp"
#include "model_status.hpp"

namespace exc {

// Whether loop closure writes the passive joints' angles into Workspace::q (one atan2 each). Every
// algorithm here works from their cosines and sines (joint_cos, joint_sin); the angles are for a
// reported state (the plant's). A controller skips them: its q's passive entries are then NaN.
enum class PassiveAngles { computed, skipped };

struct Workspace {
  explicit Workspace(const Model& model);

  // Tree state (12 joints), filled by loop closure from q_a (and qd_a).
  Vec12 q = Vec12::Zero(), qd = Vec12::Zero(), qdd = Vec12::Zero();

  // Kinematics of the tree: pose of each link in the base (swing-axis ground origin = world),
  // relative transforms f_{lambda(i),i}, body twists and accelerations, body wrenches.
  std::array<SE3, kNumJoints> X_Wi;  // front links' entries only after tree_world_poses (see there)
  bool front_world_poses_valid = true;
  std::array<SE3, kNumJoints> f_parent;
  std::array<Twist, kNumJoints> V, Vd;
  // f_parent of the front links is a pin rotation about -y by q_i (cosine, sine in joint_cos,
  // joint_sin) and f_parent's offset: set by tree_kinematics_from_front, cleared by tree_kinematics.
  // tree_kinematics_from_front writes only those entries of f_parent: the others are the constant
  // 0 and 1 of a front joint, from construction (the home translations) or tree_kinematics.
  bool pin_valid = false;
  std::array<Wrench, kNumJoints> F;
  Vec12 tau_r = Vec12::Zero();

  // Loop closure and its derivatives (model.md s.4).
  Mat8x12 H = Mat8x12::Zero();   // dh/dq
  Mat12x4 Psi = Mat12x4::Zero(); // qd = Psi qd_a (eq. 16a)
  Vec12 gamma = Vec12::Zero();   // qdd = Psi qdd_a + gamma
  Vec8 F_c = Vec8::Zero();       // loop reaction forces (eq. 7a, 7e)
  Mat12 M_r = Mat12::Zero();     // tree mass matrix (when computed)
  ModelReport report;            // last loop-closure outcome (status, loop, conditioning)

  // Tip kinematics in the swing plane (x: horizontal along the boom direction, z: up).
  Vec2 rho = Vec2::Zero(), rhod = Vec2::Zero();
  Vec2 rhodd_bias = Vec2::Zero();  // Jd_t qd_a, so rhodd = J_t qdd_a + rhodd_bias
  Mat2x4 J_t = Mat2x4::Zero();     // d rho / d q_a
  Vec3 tip_world = Vec3::Zero();

  // Planar front kinematics in the swing plane (front_kinematics.hpp): cosine and sine of the
  // absolute link angles phi, angular rates, origins and their derivatives, per tree joint (entry 0,
  // the swing, stays zero).
  std::array<double, kNumJoints> cos_phi{}, sin_phi{}, omega{}, alpha{};
  // cos q_i and sin q_i of each front pin (1 and 0 for a slide), from the loop closure's vectors or
  // from front_positions.
  std::array<double, kNumJoints> joint_cos{}, joint_sin{};
  std::array<Vec2, kNumJoints> origin, origin_d, origin_dd;
  Vec8 Hd_qd = Vec8::Zero();                    // Hd qd: cut-pin relative acceleration at qdd = 0
  Eigen::Matrix<double, 2, 12> J_tip_tree = Eigen::Matrix<double, 2, 12>::Zero();  // d rho / d q
  Vec2 tip_acc_tree = Vec2::Zero();             // rho acceleration at qdd = 0 (tree)
  // H_p^-1 at a closed configuration. There H_p is block diagonal in kPassiveJoints order (boom
  // loop, arm loop, bucket four-bar): the links common to both sides of a cut cancel.
  Mat8 Hp_inv = Mat8::Zero();
  Eigen::PartialPivLU<Mat8> lu_Hp;              // full factor of H_p (Newton loop closure)
  // H and Hp_inv are those of the last update_closed_chain. The planar path does not form them (nor
  // Hd_qd, J_tip_tree, tip_acc_tree, alpha, origin_dd, the general path's intermediates):
  // ensure_loop_jacobian forms H and Hp_inv when they are needed (inverse_dynamics' F_c).
  bool loop_jacobian_valid = false;

  // The planar path's per-link buffers (planar_closed_chain.hpp), in tree order; in the swing plane
  // (x, z) unless named otherwise. Columns k = 0..2 are the boom, arm and bucket cylinders' rates;
  // a link's columns beyond those that can move it stay zero.
  struct PlanarLinks {
    std::array<double, kNumJoints> origin_y{};     // each origin's out-of-plane offset (the homes' y summed)
    std::array<double, kNumJoints> alpha{};        // angular acceleration at qdd_a = 0 (qdd = gamma)
    std::array<Vec2, kNumJoints> acceleration;     // origin's acceleration at qdd_a = 0
    std::array<Vec2, kNumJoints> com;              // centre of mass
    std::array<double, kNumJoints> com_y{};        // its out-of-plane offset
    std::array<Vec3, kNumJoints> J_angle;          // d angle / d q_a (cylinder columns)
    std::array<Eigen::Matrix<double, 2, 3>, kNumJoints> J_origin, J_com;  // d origin, d com / d q_a
    bool jacobians_valid = false;                  // com, com_y, J_angle, J_origin, J_com
    PlanarLinks();
  } planar;
};

// Every double of the workspace, by name, to a state visitor (the shape of the firmware's
// control::StateVisitor; a template, so the model includes no floor above it): the plant's
// subnormal scan (PlantNode::scan_state, docs/floating-point.md). Held to the struct by
// `model/visit_state visits every double of Workspace once`. Not visited: lu_Hp, a factor the Newton
// loop closure forms and solves with in one call (never read across calls; Eigen asserts on reading
// one not yet formed).
template <typename Visitor>
void visit_state(const Workspace::PlanarLinks& p, Visitor& v) {
  v.visit("workspace planar origin_y", p.origin_y);
  v.visit("workspace planar alpha", p.alpha);
  for (const Vec2& a : p.acceleration) v.visit("workspace planar acceleration", a);
  for (const Vec2& c : p.com) v.visit("workspace planar com", c);
  v.visit("workspace planar com_y", p.com_y);
  for (const Vec3& j : p.J_angle) v.visit("workspace planar J_angle", j);
  for (const auto& j : p.J_origin) v.visit("workspace planar J_origin", j);
  for (const auto& j : p.J_com) v.visit("workspace planar J_com", j);
}

template <typename Visitor>
void visit_state(const Workspace& w, Visitor& v) {
  v.visit("workspace q", w.q);
  v.visit("workspace qd", w.qd);
  v.visit("workspace qdd", w.qdd);
  for (const SE3& X : w.X_Wi) v.visit("workspace X_Wi", X);
  for (const SE3& f : w.f_parent) v.visit("workspace f_parent", f);
  for (const Twist& V : w.V) v.visit("workspace V", V);
  for (const Twist& Vd : w.Vd) v.visit("workspace Vd", Vd);
  for (const Wrench& F : w.F) v.visit("workspace F", F);
  v.visit("workspace tau_r", w.tau_r);
  v.visit("workspace H", w.H);
  v.visit("workspace Psi", w.Psi);
  v.visit("workspace gamma", w.gamma);
  v.visit("workspace F_c", w.F_c);
  v.visit("workspace M_r", w.M_r);
  visit_state(w.report, v);
  v.visit("workspace rho", w.rho);
  v.visit("workspace rhod", w.rhod);
  v.visit("workspace rhodd_bias", w.rhodd_bias);
  v.visit("workspace J_t", w.J_t);
  v.visit("workspace tip_world", w.tip_world);
  v.visit("workspace cos_phi", w.cos_phi);
  v.visit("workspace sin_phi", w.sin_phi);
  v.visit("workspace omega", w.omega);
  v.visit("workspace alpha", w.alpha);
  v.visit("workspace joint_cos", w.joint_cos);
  v.visit("workspace joint_sin", w.joint_sin);
  for (const Vec2& o : w.origin) v.visit("workspace origin", o);
  for (const Vec2& o : w.origin_d) v.visit("workspace origin_d", o);
  for (const Vec2& o : w.origin_dd) v.visit("workspace origin_dd", o);
  v.visit("workspace Hd_qd", w.Hd_qd);
  v.visit("workspace J_tip_tree", w.J_tip_tree);
  v.visit("workspace tip_acc_tree", w.tip_acc_tree);
  v.visit("workspace Hp_inv", w.Hp_inv);
  visit_state(w.planar, v);
}

}  // namespace exc
