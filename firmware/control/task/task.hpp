#pragma once
// The scene's `task:` section, parsed, validated and turned into the desired joint trajectory:
//   task:
//     type: joint_waypoints        # paper 5.1: q_a waypoints, C2 spline through them
//     waypoints:                   # t in s; q = [swing rad, L_boom m, L_arm m, L_bucket m]
//       - {t: 0.0, q: [0.0, 2.30, 2.60, 1.95]}
//   task:
//     type: dig                    # paper 5.2: tip path in the swing plane
//     swing: 0.0                   # rad, held
//     path:                        # x: from the swing axis (m), z: world height (m)
//       - {t: 0.0, x: 7.0, z: 1.0, pitch_deg: -60}   # pitch: angle of M->L above swing x
//     repeat: 3                    # optional, both types: work cycles, return_time s apart
//   task:
//     type: truck_loading          # dig pass, lift and swing to the truck, dump, swing back
//     swing: 0.0                   # rad, the dig pass's swing angle
//     path: [...]                  # the dig pass, as for type dig
//     dump: {swing_deg: 90, x: 6.0, z: 3.5, pitch_deg: -40, open_pitch_deg: 45}
//     times: {to_dump: 6, dump: 2, back: 6}
//     repeat: 5
// Every field is declared once, in task_reader.cpp, with the settings reader. Errors (SettingsError)
// name the file, the line and column, the field (task.waypoints[2].q[1]) and the allowed values;
// limits (stroke, speed, reach) are checked there, before the run starts, and named at the waypoint's
// line. This header is the task as the cycle takes it; nothing here reads a file.
#include <cstddef>
#include <vector>

#include "control/task/dig_path.hpp"
#include "control/task/trajectory.hpp"
#include "settings/enum_table.hpp"

namespace exc::control {

enum class TaskType { joint_waypoints, dig, truck_loading };
inline constexpr settings::EnumTable<TaskType, 3> kTaskTypes{{{
    {TaskType::joint_waypoints, "joint_waypoints", "paper 5.1: q_a waypoints, a C2 spline through them"},
    {TaskType::dig, "dig", "paper 5.2: a bucket-tip path in the swing plane"},
    {TaskType::truck_loading, "truck_loading", "dig pass, lift and swing to the truck, dump, swing back"},
}}};

// The effort check before the run (effort_feasibility.hpp), from the task's `efforts:` mapping.
struct TaskEffortCheck {
  bool check = true;        // refuse a path the actuators cannot drive
  double soil_margin = 0.3; // fraction of each limit kept for the soil where the tip is below ground
  bool fit_timing = false;  // instead of refusing, slow the whole path down until it fits
};

struct Task {
  TaskType type = TaskType::joint_waypoints;
  JointTrajectory trajectory;
  std::vector<double> waypoint_times;  // of the waypoints or tip poses given in the file
  double swing = 0;                    // dig: the held swing angle
  std::vector<DigWaypoint> path;       // dig: the tip poses as given
  double start_time() const { return trajectory.start_time(); }
  double end_time() const { return trajectory.end_time(); }
  TaskEffortCheck efforts;
  // Work cycles (repeat: N): the trajectory time at which each cycle starts (one entry for a task
  // done once). Cycle k+1 begins with the return move from where cycle k ended.
  std::vector<double> cycle_starts;
  int cycles() const { return static_cast<int>(cycle_starts.size()); }
  double timing_scale = 1;             // > 1 when fit_timing slowed the path down (times multiplied)
};

// The most work cycles a task has (task.repeat's upper bound), as the settings blob carries them.
inline constexpr std::size_t kMaxTaskCycles = 1000;

// The settings blob's field list (app/settings_blob.hpp): what the cycle and a run's record read.
// Left out: waypoint_times, swing, path and efforts, from which the reader built and checked the
// trajectory on the host.
template <typename Visitor>
void visit_fields(Visitor& v, Task& t) {
  v.choice("type", t.type, kTaskTypes);
  v("trajectory", t.trajectory);
  v("cycle_starts", t.cycle_starts, kMaxTaskCycles);
  v("timing_scale", t.timing_scale);
}

}  // namespace exc::control
