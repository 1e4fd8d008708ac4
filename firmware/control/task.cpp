#include "control/task.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>

#include "control/config_fields.hpp"
#include "control/work_cycle.hpp"

namespace exc::control {
namespace {

bool read_flag(const YAML::Node& n, const std::string& file, const std::string& field) {
  bool v = false;
  if (!n.IsScalar() || !YAML::convert<bool>::decode(n, v)) throw ConfigError(file, field, "must be true or false");
  return v;
}

TaskEffortCheck parse_effort_check(const YAML::Node& n, const std::string& file, const std::string& field) {
  TaskEffortCheck c;
  if (!n.IsDefined() || n.IsNull()) return c;
  reject_unknown_keys(n, file, field, {"check", "soil_margin", "fit_timing"});
  if (n["check"]) c.check = read_flag(n["check"], file, field + ".check");
  if (n["soil_margin"]) c.soil_margin = read_number(n["soil_margin"], file, field + ".soil_margin", 0, 0.9);
  if (n["fit_timing"]) c.fit_timing = read_flag(n["fit_timing"], file, field + ".fit_timing");
  return c;
}

constexpr double kPi = 3.14159265358979323846;
constexpr double kTimeMax = 1e5;

const YAML::Node& sequence(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsDefined() || !n.IsSequence() || n.size() < 2)
    throw ConfigError(file, field, "must be a list of at least 2 waypoints");
  return n;
}

// A tip path (the dig pass): timed tip poses.
std::vector<DigWaypoint> parse_path(const YAML::Node& node, const std::string& file, const std::string& field) {
  const YAML::Node p = sequence(node, file, field);
  std::vector<DigWaypoint> path;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const std::string f = field + "[" + std::to_string(i) + "]";
    reject_unknown_keys(p[i], file, f, {"t", "x", "z", "pitch_deg"});
    DigWaypoint wp;
    wp.t = read_number(p[i]["t"], file, f + ".t", 0, kTimeMax, "s");
    wp.pose.x = read_number(p[i]["x"], file, f + ".x", 0, 100, "m");
    wp.pose.z = read_number(p[i]["z"], file, f + ".z", -100, 100, "m");
    wp.pose.pitch = read_number(p[i]["pitch_deg"], file, f + ".pitch_deg", -360, 360, "deg") * kPi / 180;
    path.push_back(wp);
  }
  return path;
}

}  // namespace

Task parse_task(const YAML::Node& node, const std::string& file, const Machine& machine,
                const TrajectoryCheckOptions& options) {
  const std::string s = "task";
  if (!node.IsDefined() || node.IsNull()) throw ConfigError(file, s, "missing (type: joint_waypoints or dig)");
  if (!node.IsMap()) throw ConfigError(file, s, "must be a mapping with a type");
  const std::string type = node["type"] ? node["type"].as<std::string>() : "";
  Task task;
  int repeat = 1;
  double return_time = 3;
  if (node["repeat"]) repeat = static_cast<int>(read_number(node["repeat"], file, s + ".repeat", 1, 1000));
  if (node["return_time"]) return_time = read_number(node["return_time"], file, s + ".return_time", 0.1, 600, "s");
  if (type == "joint_waypoints") {
    reject_unknown_keys(node, file, s, {"type", "waypoints", "efforts", "repeat", "return_time"});
    task.type = TaskType::joint_waypoints;
    const YAML::Node w = sequence(node["waypoints"], file, s + ".waypoints");
    const Vec4 lo = machine.q_min(), hi = machine.q_max();
    std::vector<Vec4> qs;
    for (std::size_t i = 0; i < w.size(); ++i) {
      const std::string f = s + ".waypoints[" + std::to_string(i) + "]";
      reject_unknown_keys(w[i], file, f, {"t", "q"});
      const double t = read_number(w[i]["t"], file, f + ".t", 0, kTimeMax, "s");
      if (!task.waypoint_times.empty() && !(t > task.waypoint_times.back()))
        throw ConfigError(file, f + ".t", format_number(t) + " s must be later than the previous waypoint's " +
                                              format_number(task.waypoint_times.back()) + " s");
      const YAML::Node q = w[i]["q"];
      if (!q.IsDefined() || !q.IsSequence() || q.size() != kNumActive)
        throw ConfigError(file, f + ".q", "must be 4 numbers [swing rad, L_boom m, L_arm m, L_bucket m]");
      Vec4 v;
      for (int j = 0; j < kNumActive; ++j) {
        const double l = std::isfinite(lo[j]) ? lo[j] : -1e3, h = std::isfinite(hi[j]) ? hi[j] : 1e3;
        v[j] = read_number(q[j], file, f + ".q[" + std::to_string(j) + "]", l, h, j == 0 ? "rad" : "m");
      }
      task.waypoint_times.push_back(t);
      qs.push_back(v);
    }
    task.trajectory = JointTrajectory(task.waypoint_times, qs);
    check_joint_trajectory(machine, task.trajectory, task.waypoint_times, options, file, s + ".waypoints");
  } else if (type == "dig") {
    reject_unknown_keys(node, file, s, {"type", "swing", "path", "efforts", "repeat", "return_time"});
    task.type = TaskType::dig;
    task.swing = node["swing"] ? read_number(node["swing"], file, s + ".swing", -kPi, kPi, "rad") : 0.0;
    task.path = parse_path(node["path"], file, s + ".path");
    for (const DigWaypoint& w : task.path) task.waypoint_times.push_back(w.t);
    task.trajectory = dig_trajectory(machine, task.swing, task.path, options, file, s + ".path");
  } else if (type == "truck_loading") {
    reject_unknown_keys(node, file, s, {"type", "swing", "path", "dump", "times", "repeat", "efforts"});
    task.type = TaskType::truck_loading;
    task.swing = node["swing"] ? read_number(node["swing"], file, s + ".swing", -kPi, kPi, "rad") : 0.0;
    task.path = parse_path(node["path"], file, s + ".path");
    for (const DigWaypoint& w : task.path) task.waypoint_times.push_back(w.t);
    const YAML::Node d = node["dump"];
    if (!d.IsDefined() || !d.IsMap()) throw ConfigError(file, s + ".dump", "missing: {swing_deg, x, z, pitch_deg, open_pitch_deg}");
    reject_unknown_keys(d, file, s + ".dump", {"swing_deg", "x", "z", "pitch_deg", "open_pitch_deg"});
    DumpPose dump;
    dump.swing = read_number(d["swing_deg"], file, s + ".dump.swing_deg", -180, 180, "deg") * kPi / 180;
    dump.curled.x = read_number(d["x"], file, s + ".dump.x", 0, 100, "m");
    dump.curled.z = read_number(d["z"], file, s + ".dump.z", -100, 100, "m");
    dump.curled.pitch = read_number(d["pitch_deg"], file, s + ".dump.pitch_deg", -360, 360, "deg") * kPi / 180;
    dump.open_pitch = read_number(d["open_pitch_deg"], file, s + ".dump.open_pitch_deg", -360, 360, "deg") * kPi / 180;
    TruckCycleTimes times;
    if (const YAML::Node t = node["times"]) {
      reject_unknown_keys(t, file, s + ".times", {"to_dump", "dump", "back"});
      if (t["to_dump"]) times.to_dump = read_number(t["to_dump"], file, s + ".times.to_dump", 0.5, 600, "s");
      if (t["dump"]) times.dump = read_number(t["dump"], file, s + ".times.dump", 0.2, 600, "s");
      if (t["back"]) times.back = read_number(t["back"], file, s + ".times.back", 0.5, 600, "s");
    }
    const CycleKnots cycle = truck_loading_cycle(machine, task.swing, task.path, dump, times, options, file, s);
    // Each cycle after the first starts with the swing back (the return move); the last one swings
    // back too, so the machine ends where the next pass would start.
    const CycleKnots all = repeat_cycle(cycle, repeat + 1, times.back, task.cycle_starts);
    const std::size_t last_start =
        static_cast<std::size_t>(std::lower_bound(all.times.begin(), all.times.end(), task.cycle_starts.back()) - all.times.begin());
    task.cycle_starts.pop_back();
    task.trajectory = JointTrajectory(std::vector<double>(all.times.begin(), all.times.begin() + last_start + 1),
                                      std::vector<Vec4>(all.points.begin(), all.points.begin() + last_start + 1));
    check_joint_trajectory(machine, task.trajectory, task.cycle_starts, options, file, s + ".cycle");
    task.efforts = parse_effort_check(node["efforts"], file, s + ".efforts");
    return task;
  } else {
    throw ConfigError(file, s + ".type", "'" + type + "' (allowed: joint_waypoints, dig, truck_loading)");
  }
  // Work cycles of a joint or dig task: one spline through the repeated knots.
  if (repeat > 1) {
    const CycleKnots once{task.trajectory.times(), task.trajectory.points()};
    const CycleKnots all = repeat_cycle(once, repeat, return_time, task.cycle_starts);
    task.trajectory = JointTrajectory(all.times, all.points);
    check_joint_trajectory(machine, task.trajectory, task.cycle_starts, options, file, s + ".cycle");
  } else {
    task.cycle_starts = {task.trajectory.start_time()};
  }
  task.efforts = parse_effort_check(node["efforts"], file, s + ".efforts");
  return task;
}

Task load_task(const std::string& scene_path, const Machine& machine, const TrajectoryCheckOptions& options) {
  const YAML::Node root = load_yaml_file(scene_path);
  return parse_task(root["task"], scene_path, machine, options);
}

}  // namespace exc::control
