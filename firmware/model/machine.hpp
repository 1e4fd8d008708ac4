#pragma once
// The machine description (pins, bodies, limits) as read from a machine file such as
// machines/reference-20t.yaml. Loading validates every field; errors name file, field and reason.
// This is start-up code: it may allocate. Nothing built from it allocates afterwards.
#include <stdexcept>
#include <string>
#include <vector>

#include "types.hpp"

namespace exc {

// A load-time error: which file, which field (dotted path, e.g. "bodies.boom.mass") and why.
class MachineError : public std::runtime_error {
 public:
  MachineError(std::string file, std::string field, std::string reason);
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_, field_, reason_;
};

struct BodyInertia {
  double mass = 0;             // kg
  Vec3 com = Vec3::Zero();     // centre of mass in the body frame (m)
  Vec3 inertia = Vec3::Zero(); // principal inertia about the com, body axes [Ixx Iyy Izz] (kg m^2)
};

struct CylinderLimits {
  double min_length = 0, max_length = 0;  // pin to pin (m)
  double min_force = 0, max_force = 0;    // N (negative = pull)
  double max_speed = 0;                   // m/s
};

struct SwingLimits {
  double min_torque = 0, max_torque = 0;  // N m
  double max_speed = 0;                   // rad/s
};

struct ReferencePose {
  Vec4 q_a = Vec4::Zero();
  double boom_angle_deg = 0, arm_angle_deg = 0, bucket_angle_deg = 0;
  // World positions of the named pins (C, E, H, G, M, J, L, T), in this order when present.
  std::vector<std::pair<std::string, Vec3>> pins_world;
};

struct Machine {
  std::string name;
  std::string source;    // file the machine was loaded from ("<embedded>" for the built-in one)
  double gravity = 9.81; // m/s^2, along -z
  double swing_height = 0;

  // Planar pins (x, z) in the frame of their section (see the machine file's 'frames').
  Vec2 C, D;        // swing frame
  Vec2 E, F, H;     // boom frame
  Vec2 G, I, K, M;  // arm frame
  Vec2 L, T;        // bucket frame (T: tip)
  double JL = 0, JK = 0;  // link lengths

  std::array<BodyInertia, kNumJoints> bodies;  // indexed by JointIndex

  SwingLimits swing;
  CylinderLimits boom, arm, bucket;
  double relief_pressure = 0;  // Pa

  std::vector<ReferencePose> reference_poses;
  double terrain_flat_height = 0;

  // Limits of the active coordinates, q_a order: swing (+-inf if unlimited), then cylinder lengths.
  Vec4 q_min() const;
  Vec4 q_max() const;
  Vec4 effort_min() const;
  Vec4 effort_max() const;
  Vec4 speed_max() const;
};

// Reads and validates a machine file. Throws MachineError.
Machine load_machine(const std::string& path);
// Same, from YAML text; 'file_for_errors' is what errors name as the file.
Machine load_machine_from_string(const std::string& yaml, const std::string& file_for_errors);
// The reference machine compiled into the binary (same numbers as machines/reference-20t.yaml).
Machine reference_machine();

}  // namespace exc
