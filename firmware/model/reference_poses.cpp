#include "model/reference_poses.hpp"

#include <cmath>
#include <cstdio>

#include "model/closed_chain.hpp"
#include "model/lie_group.hpp"
#include "model/newton_euler.hpp"

namespace exc {

namespace {
constexpr double kDegPerRad = 180.0 / 3.14159265358979323846;

std::string xyz(const Vec3& p) {
  char text[96];
  std::snprintf(text, sizeof text, "(%.4f, %.4f, %.4f)", p.x(), p.y(), p.z());
  return text;
}
}  // namespace

Vec3 pin_in_world(const Model& model, const Workspace& ws, const std::string& name) {
  const Machine& k = model.machine;
  if (name == "C") return translation(ws.X_Wi[kBoom]);
  if (name == "E") return translation(ws.X_Wi[kBoomRod]);  // the rod-end frame's origin
  if (name == "H") return translation(ws.X_Wi[kArm]);
  if (name == "G") return translation(ws.X_Wi[kArmRod]);
  if (name == "M") return translation(ws.X_Wi[kBucket]);
  if (name == "J") return translation(ws.X_Wi[kBucketRod]);
  if (name == "L") return (ws.X_Wi[kBucket] * Eigen::Vector4d(k.L.x(), 0.0, k.L.y(), 1.0)).head<3>();
  if (name == "T") return ws.tip_world;
  return Vec3::Constant(std::nan(""));
}

std::optional<PoseMismatch> check_reference_pose(const Model& model, const ReferencePose& pose) {
  Workspace ws(model);
  const ModelReport report = update_closed_chain(model, ws, pose.q_a, Vec4::Zero());
  if (!report.ok())
    return PoseMismatch{"q_a", std::string("the geometry does not assemble at it: ") + to_string(report.status)};
  tree_world_poses(model, ws);
  const struct {
    const char* field;
    double model_deg, file_deg;
  } angles[] = {{"boom_angle_deg", ws.q[kBoom] * kDegPerRad, pose.boom_angle_deg},
                {"arm_angle_deg", ws.q[kArm] * kDegPerRad, pose.arm_angle_deg},
                {"bucket_angle_deg", ws.q[kBucket] * kDegPerRad, pose.bucket_angle_deg}};
  for (const auto& a : angles) {
    if (std::abs(a.model_deg - a.file_deg) > kPoseAngleTolerance) {
      char text[160];
      std::snprintf(text, sizeof text, "the geometry gives %.3f deg at this q_a, the pose %.3f (tolerance %.2f deg)",
                    a.model_deg, a.file_deg, kPoseAngleTolerance);
      return PoseMismatch{a.field, text};
    }
  }
  for (const auto& [name, p] : pose.pins_world) {
    const Vec3 at = pin_in_world(model, ws, name);
    const double off = (at - p).norm();
    if (!(off <= kPosePinTolerance)) {
      char text[64];
      std::snprintf(text, sizeof text, ", %.1f mm away (tolerance %.1f mm)", off * 1e3, kPosePinTolerance * 1e3);
      return PoseMismatch{"pins_world." + name, "the geometry puts pin " + name + " at " + xyz(at) + ", the pose at " +
                                                    xyz(p) + text};
    }
  }
  return std::nullopt;
}

}  // namespace exc
