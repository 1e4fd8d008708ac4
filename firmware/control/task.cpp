#include "control/task.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "control/config_fields.hpp"

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

const YAML::Node& sequence(const YAML::Node& n, const std::string& file, const std::string& field) {
  if (!n.IsDefined() || !n.IsSequence() || n.size() < 2)
    throw ConfigError(file, field, "must be a list of at least 2 waypoints");
  return n;
}

}  // namespace

Task parse_task(const YAML::Node& node, const std::string& file, const Machine& machine,
                const TrajectoryCheckOptions& options) {
  const std::string s = "task";
  if (!node.IsDefined() || node.IsNull()) throw ConfigError(file, s, "missing (type: joint_waypoints or dig)");
  if (!node.IsMap()) throw ConfigError(file, s, "must be a mapping with a type");
  const std::string type = node["type"] ? node["type"].as<std::string>() : "";
  Task task;
  constexpr double kTimeMax = 1e5;
  if (type == "joint_waypoints") {
    reject_unknown_keys(node, file, s, {"type", "waypoints", "efforts"});
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
    reject_unknown_keys(node, file, s, {"type", "swing", "path", "efforts"});
    task.type = TaskType::dig;
    task.swing = node["swing"] ? read_number(node["swing"], file, s + ".swing", -3.14159265358979323846,
                                        3.14159265358979323846, "rad")
                               : 0.0;
    const YAML::Node p = sequence(node["path"], file, s + ".path");
    for (std::size_t i = 0; i < p.size(); ++i) {
      const std::string f = s + ".path[" + std::to_string(i) + "]";
      reject_unknown_keys(p[i], file, f, {"t", "x", "z", "pitch_deg"});
      DigWaypoint wp;
      wp.t = read_number(p[i]["t"], file, f + ".t", 0, kTimeMax, "s");
      wp.pose.x = read_number(p[i]["x"], file, f + ".x", 0, 100, "m");
      wp.pose.z = read_number(p[i]["z"], file, f + ".z", -100, 100, "m");
      wp.pose.pitch = read_number(p[i]["pitch_deg"], file, f + ".pitch_deg", -360, 360, "deg") * 3.14159265358979323846 / 180;
      task.path.push_back(wp);
      task.waypoint_times.push_back(wp.t);
    }
    task.trajectory = dig_trajectory(machine, task.swing, task.path, options, file, s + ".path");
  } else {
    throw ConfigError(file, s + ".type", "'" + type + "' (allowed: joint_waypoints, dig)");
  }
  task.efforts = parse_effort_check(node["efforts"], file, s + ".efforts");
  return task;
}

Task load_task(const std::string& scene_path, const Machine& machine, const TrajectoryCheckOptions& options) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(scene_path);
  } catch (const YAML::BadFile&) {
    throw ConfigError(scene_path, "", "cannot open the file");
  } catch (const YAML::Exception& e) {
    throw ConfigError(scene_path, "", std::string("not valid YAML: ") + e.what());
  }
  return parse_task(root["task"], scene_path, machine, options);
}

}  // namespace exc::control
