#pragma once
// The constant multibody description built once from a Machine (Pinocchio's Model): the 12-link tree
// of paper Table 1 with home transforms M_i, screws S_i, spatial inertias J_i, and the 4 cut pins of
// Table 2. Link frames are those of the machine file ('frames'); every front pin axis is y.
#include "machine.hpp"

namespace exc {

struct LoopCut {
  int link_p = 0, link_s = 0;   // JointIndex of P_l and S_l (Table 2)
  Vec3 point_p, point_s;        // the pin, in the frame of P_l and of S_l
};

// How update_closed_chain, mass_matrix and bias_forces evaluate the closed chain (docs/model.md):
// `planar`, straight-line code written for this machine's planar front and its four loops
// (planar_closed_chain.hpp), or `general`, the Lie-group passes over any tree and the loop Jacobian
// (the reference the planar code is tested against). build_model takes planar when the tree has
// that structure and the process has not asked for general (set_closed_chain_path_preference).
enum class ClosedChainPath { planar, general };

struct Model {
  Machine machine;                         // the description it was built from
  std::array<int, kNumJoints> parent;      // JointIndex of lambda(k), -1 for the base
  std::array<SE3, kNumJoints> home;        // M_i: parent frame -> frame i at q_i = 0
  std::array<Twist, kNumJoints> screw;     // S_i in frame i
  std::array<bool, kNumJoints> prismatic;
  std::array<bool, kNumJoints> home_is_translation;  // M_i has no rotation (true for this machine)
  // Swing about z at the base, every other joint a pin about -y or a slide along x, all homes
  // translations: the tree poses can then come from the planar front pass (set by build_model).
  bool planar_front = false;
  std::array<Mat6, kNumJoints> inertia;    // J_i about the frame origin, (w, v) ordering
  std::array<Mat3, kNumJoints> inertia_in_plane;  // J_i on (w_y, v_x, v_z): the planar front's block
  std::array<LoopCut, kNumLoops> loops;
  Vec3 tip_in_bucket;                      // T in the bucket frame
  Vec6 base_acceleration;                  // Vd_0 = (0, 0, 0, 0, 0, +g): gravity (model.md s.3)
  ClosedChainPath closed_chain_path = ClosedChainPath::general;
};

Model build_model(const Machine& machine);

// The path the models built from now on take where the planar one applies (default planar). For
// benches that measure both in one run and tests that compare them; set before building models.
void set_closed_chain_path_preference(ClosedChainPath path);
ClosedChainPath closed_chain_path_preference();

}  // namespace exc
