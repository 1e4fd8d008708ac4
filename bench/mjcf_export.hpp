#pragma once
// Exports the project's machine to MJCF (MuJoCo's XML), so MuJoCo can be run as a peer on the very
// same mechanism: the 12-link tree of paper Table 1 as nested bodies with one hinge or slide joint
// each, the 4 loops of Table 2 as `connect` equality constraints at the cut pins (E, G, K, L), the
// swing motor and the three cylinders as `motor` actuators with gear 1 (ctrl = our tau_a).
// The bodies are written at a closed configuration (joint `ref` = our q there), because MuJoCo
// places the second anchor of each connect constraint from the model's reference configuration.
// qpos of joint k equals our tree coordinate q_k (same axes, same zero).
#include <array>
#include <string>

#include "model/model.hpp"

namespace exc::bench {

// Body (and joint) names in JointIndex order; the actuators are named after kActiveNames.
extern const std::array<const char*, kNumJoints> kMjcfBodyNames;

struct MjcfOptions {
  double timestep = 1e-3;              // s, the plant's cycle
  const char* integrator = "Euler";    // MuJoCo's semi-implicit Euler, like the plant's default
  // Time constant of the connect constraints (solref), s. 0: twice the timestep, the stiffest
  // MuJoCo integrates stably, i.e. the smallest loop-closure error MuJoCo can be asked for.
  double constraint_time_constant = 0;
  double constraint_damping_ratio = 1.0;
  // solimp d0 d_width width: impedance close to 1 makes the constraint nearly hard.
  double impedance_min = 0.95, impedance_max = 0.99, impedance_width = 0.001;
};

// The MJCF text of 'model' assembled at q_a_reference (loop closure by the model's closed form).
// Throws std::runtime_error naming the pose when the loops cannot close there.
std::string export_mjcf(const Model& model, const Vec4& q_a_reference, const MjcfOptions& options = {});

}  // namespace exc::bench
