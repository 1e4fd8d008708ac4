#pragma once
// A machine file's measured poses against the model its geometry builds: each pose's joint angles
// and named pins, as the file gives them, must be what the closed chain assembles at its q_a
// (0.01 deg, 0.5 mm: the file's four and five decimals). A file whose geometry was edited without
// its poses (or the reverse) is refused when it loads, naming the pose's field.
#include <optional>
#include <string>

#include "model/machine.hpp"
#include "model/model.hpp"
#include "model/workspace.hpp"

namespace exc {

inline constexpr double kPoseAngleTolerance = 0.01;  // deg
inline constexpr double kPosePinTolerance = 0.5e-3;  // m

// World position of a named pin (C, E, H, G, M, J, L, T) in the assembled pose held by `ws`
// (after update_closed_chain and tree_world_poses).
Vec3 pin_in_world(const Model& model, const Workspace& ws, const std::string& name);

struct PoseMismatch {
  std::string field;   // within the pose: "q_a", "boom_angle_deg", "pins_world.G"
  std::string reason;  // what the model gives against what the file says
};

// The first disagreement of `pose` with `model`, or none.
std::optional<PoseMismatch> check_reference_pose(const Model& model, const ReferencePose& pose);

}  // namespace exc
