#include "app/firmware_settings.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>

#include "control/config_fields.hpp"
#include "control/effort_feasibility.hpp"
#include "model/model.hpp"

namespace exc::app {
namespace {

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? "." : path.substr(0, slash);
}

std::string resolve(const std::string& base, const std::string& path) {
  if (path.empty() || path[0] == '/') return path;
  return base + "/" + path;
}

// The task against the actuators' limits before the run: refused with the place, the joint and the
// effort, or (task.efforts.fit_timing) slowed down until it fits, 2 % beyond the exact fit.
void check_task_efforts(FirmwareSettings& s) {
  control::Task& task = s.task;
  if (!task.efforts.check) return;
  control::FeasibilityOptions o;
  o.soil_margin = task.efforts.soil_margin;
  o.terrain_height = s.terrain_height;
  const Model model = build_model(s.machine);
  const control::FeasibilityReport r = control::check_effort_feasibility(model, task.trajectory, o);
  if (r.ok) return;
  // The place is named by waypoint for a task done once, by cycle for work cycles.
  const bool cycles = task.cycles() > 1 || task.type == control::TaskType::truck_loading;
  const std::string field = cycles ? "task.cycle" : task.type == control::TaskType::dig ? "task.path" : "task.waypoints";
  std::vector<double> marks = cycles ? task.cycle_starts : task.waypoint_times;
  if (cycles) marks.push_back(task.end_time());
  if (!task.efforts.fit_timing || std::isinf(r.time_scale))
    throw control::ConfigError(s.file, field, r.message(marks, field) +
                                                  (std::isinf(r.time_scale) ? "" : "; or set task.efforts.fit_timing: true"));
  task.timing_scale = r.time_scale * 1.02;
  task.trajectory = control::scale_timing(task.trajectory, task.timing_scale);
  const double t0 = task.waypoint_times.front();
  for (double& t : task.waypoint_times) t = t0 + (t - t0) * task.timing_scale;
  for (double& t : task.cycle_starts) t = t0 + (t - t0) * task.timing_scale;
  for (control::DigWaypoint& w : task.path) w.t = t0 + (w.t - t0) * task.timing_scale;
}

}  // namespace

FirmwareSettings parse_firmware_settings(const YAML::Node& root, const std::string& file,
                                         const std::string& base_directory) {
  using control::ConfigError;
  if (!root || !root.IsMap()) throw ConfigError(file, "", "the scene must be a YAML mapping");
  // The firmware's sections, then the plant's (read by sim_plant; named here only so that a
  // misspelt section is refused by the firmware too).
  control::reject_unknown_keys(root, file, "", {"name", "description", "machine", "terrain", "duration", "controller",
                                                "task", "soil", "initial_state", "actuators", "integrator",
                                                "sensors", "checks"});
  FirmwareSettings s;
  s.file = file;
  if (!root["name"] || !root["name"].IsScalar()) throw ConfigError(file, "name", "missing; a string");
  s.name = root["name"].as<std::string>();
  if (root["machine"]) {
    if (!root["machine"].IsScalar()) throw ConfigError(file, "machine", "must be the path of a machine file");
    s.machine_file = resolve(base_directory, root["machine"].as<std::string>());
    try {
      s.machine = load_machine(s.machine_file);
    } catch (const MachineError& e) {
      throw ConfigError(file, "machine", std::string("the machine file does not load: ") + e.what());
    }
  } else {
    s.machine = reference_machine();
  }
  s.terrain_height = s.machine.terrain_flat_height;
  if (const YAML::Node terrain = root["terrain"]; terrain && terrain["height"])
    s.terrain_height = control::read_number(terrain["height"], file, "terrain.height", -20, 20, "m");
  s.duration = control::read_number(root["duration"], file, "duration", 1e-3, 28800, "s");  // a working shift
  s.controller = control::parse_controller_config(root["controller"], file);
  if (!root["task"]) throw ConfigError(file, "task", "missing: the firmware needs a task");
  s.task = control::parse_task(root["task"], file, s.machine);
  check_task_efforts(s);
  return s;
}

FirmwareSettings load_firmware_settings(const std::string& path) {
  const YAML::Node root = control::load_yaml_file(path);
  return parse_firmware_settings(root, path, directory_of(path));
}

}  // namespace exc::app
