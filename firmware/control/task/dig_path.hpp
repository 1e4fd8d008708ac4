#pragma once
// The digging pass (the paper's 5.2): a bucket-tip path in the swing plane (approach, penetrate,
// drag, curl, lift), given as timed tip poses, turned into a cylinder-length trajectory:
//   1. a C2 spline through the tip poses (x, z, pitch) with zero end velocities;
//   2. sampled every sample_period; each sample through the closed-form inverse kinematics;
//   3. a C2 joint spline through the samples (the swing angle held).
// Before the run starts every sample is checked: reachable, bucket linkage closes, cylinder lengths
// inside the stroke (with a margin), cylinder speeds below the machine's limits. An error names the
// waypoint (task.path[i]) or the segment between two, the time, the value and the allowed range.
// Start-up code: allocates, throws SettingsError.
#include <string>
#include <vector>

#include "control/task/inverse_kinematics.hpp"
#include "control/task/trajectory.hpp"

namespace exc::control {

struct DigWaypoint {
  double t = 0;      // s
  TipPose pose;      // x, z (world height), pitch (rad)
};

struct TrajectoryCheckOptions {
  double sample_period = 0.01;  // s, IK sampling of the tip path, and the limit-check grid
  double length_margin = 0.0;   // m kept away from each end of the stroke
  bool check_speed = true;      // cylinder and swing speeds against the machine's limits
};

// Throws SettingsError naming 'field' (e.g. "task.path") with the index of the offending waypoint.
JointTrajectory dig_trajectory(const Machine& machine, double swing, const std::vector<DigWaypoint>& path,
                               const TrajectoryCheckOptions& options, const std::string& file,
                               const std::string& field = "task.path");

// Checks a joint trajectory on a grid against the stroke and speed limits; 'field' and the waypoint
// times name the place in errors ("task.waypoints[2] -> task.waypoints[3] at t = 1.25 s: ...").
void check_joint_trajectory(const Machine& machine, const JointTrajectory& trajectory,
                            const std::vector<double>& waypoint_times, const TrajectoryCheckOptions& options,
                            const std::string& file, const std::string& field);

// "task.path[2]" when t is (within 1e-9 s) a waypoint time, else "task.path[2] -> task.path[3]".
std::string waypoint_place(const std::vector<double>& times, double t, const std::string& field);

}  // namespace exc::control
