#include "app/firmware_settings.hpp"

#include <algorithm>
#include <cmath>

#include "app/firmware_node.hpp"
#include "control/task/effort_feasibility.hpp"
#include "control/task/pump_pacing.hpp"
#include "model/actuator_friction.hpp"
#include "model/model.hpp"
#include "model/plant_scene_keys.hpp"
#include "model/scene_common_reader.hpp"
#include "control/controller_config_reader.hpp"
#include "control/controller_registry.hpp"
#include "control/task/task_reader.hpp"

namespace exc::app {
namespace {

// Seconds rounded up to whole control cycles (the run steps by them; a rounding error below 1e-9 of
// a cycle adds none).
double whole_cycles_up(double seconds, double period) { return period * std::ceil(seconds / period - 1e-9); }

// The task against the actuators' limits before the run: refused with the place, the joint and the
// effort, or (task.efforts.fit_timing) slowed down until it fits, 2 % beyond the exact fit, and the
// run's duration with it.
void check_task_efforts(FirmwareSettings& s) {
  control::Task& task = s.task;
  if (!task.efforts.check) return;
  control::FeasibilityOptions o;
  o.soil_margin = task.efforts.soil_margin;
  o.terrain = s.terrain;
  if (s.controller.command_interface == control::CommandInterface::valve) {
    // A hydraulic machine: its seals and the swing motor's breakaway take part of each limit.
    const double pump = s.machine.hydraulics.pump_pressure_limit();
    o.friction = coulomb_level(actuator_friction(s.machine), Vec4::Constant(pump), Vec4::Zero());
  }
  const Model model = build_model(s.machine);
  const control::FeasibilityReport r = control::check_effort_feasibility(model, task.trajectory, o);
  if (r.ok) return;
  // The place is named by waypoint for a task done once, by cycle for work cycles.
  const bool cycles = task.cycles() > 1 || task.type == control::TaskType::truck_loading;
  const std::string field = cycles ? "task.cycle" : task.type == control::TaskType::dig ? "task.path" : "task.waypoints";
  std::vector<double> marks = cycles ? task.cycle_starts : task.waypoint_times;
  if (cycles) marks.push_back(task.end_time());
  if (!task.efforts.fit_timing || std::isinf(r.time_scale))
    throw SettingsError(s.file, 0, 0, field, r.message(marks, field) +
                                             (std::isinf(r.time_scale) ? "" : "; or set task.efforts.fit_timing: true"));
  task.timing_scale = r.time_scale * 1.02;
  // A run that covered the path (its duration at least the path's) covers the stretched path, and
  // the time it had after it, at least until the task has finished (tracking begins after the node's
  // track delay); a run asked to cover only part of the path keeps its duration.
  const double path_time = task.end_time() - task.start_time();
  const double after = std::max(s.duration - path_time, FirmwareNodeConfig{}.track_delay + s.controller.period);
  if (s.duration >= path_time) s.duration = whole_cycles_up(path_time * task.timing_scale + after, s.controller.period);
  task.trajectory = control::scale_timing(task.trajectory, task.timing_scale);
  const double t0 = task.waypoint_times.front();
  for (double& t : task.waypoint_times) t = t0 + (t - t0) * task.timing_scale;
  for (double& t : task.cycle_starts) t = t0 + (t - t0) * task.timing_scale;
  for (control::DigWaypoint& w : task.path) w.t = t0 + (w.t - t0) * task.timing_scale;
}

// Each law the scene may run (the one it names, else every law its command interface carries) built
// once while the file is at hand, so that what only a law's construction can find (eq. 24's Lyapunov
// equation without a positive definite solution) is refused at the scene's line and key, not as a
// bare message when a run starts. A law's SettingsError names its key (controller.kv, ...) and no
// file: the file is this scene's.
void check_laws_build(const FirmwareSettings& s) {
  const Model model = build_model(s.machine);
  for (const control::ControllerEntry& law : control::controller_registry().entries()) {
    if (s.controller.law_given ? law.name != s.controller.law
                               : !control::interface_misfit(law, s.controller.command_interface).empty())
      continue;
    control::ControllerConfig c = s.controller;
    c.law = law.name;
    try {
      law.make(model, c);
    } catch (const SettingsError& e) {
      throw SettingsError(s.file, 0, 0, e.field(), "the " + law.name + " law cannot be built: " + e.reason());
    }
  }
}

// A paced path (controller.pump_pacing) takes longer than its times say: a run that covered the
// path covers the paced one, estimated without the clock's lag, plus a tenth and the lag's settling
// (4 T) for what the lag adds.
void extend_for_pump_pacing(FirmwareSettings& s) {
  if (!s.controller.path_clock.pump_pacing) return;
  const double period = s.controller.period;
  const control::JointTrajectory& path = s.task.trajectory;
  const control::PumpPacing pacing(s.machine, s.controller.path_clock.pump_pacing_share, period);
  const double path_time = path.end_time() - path.start_time();
  const double paced = control::paced_duration(pacing, path, period);
  // Stepped in whole periods, an unpaced path comes out up to a period longer: no time added for it.
  if (s.duration >= path_time && paced > path_time + 2 * period)
    s.duration += whole_cycles_up(1.1 * (paced - path_time) + 4 * control::PumpPacing::kTimeConstant, period);
}

}  // namespace

FirmwareSettings read_firmware_settings(const settings::Document& scene, const SceneMachine& machine) {
  settings::SectionReader top(scene);
  FirmwareSettings s;
  s.file = scene.file();
  SceneCommon common = read_scene_common(top, machine);
  s.name = common.name;
  s.machine_file = common.machine_file;
  s.machine = std::move(common.machine);
  s.terrain = common.terrain;
  s.duration = s.scene_duration = common.duration;
  settings::SectionReader controller = top.section("controller", "the control law's settings");
  control::read_controller_config(controller, s.controller, s.machine);
  settings::SectionReader task = top.section("task", "what the machine does");
  s.task = control::read_task(task, s.machine);
  top.others(kPlantSceneSections);
  top.finish();
  // The plant's sections: their values are the plant's to read, their keys named here too, so a
  // misspelt one is refused by the firmware as by the plant.
  check_plant_scene_keys(scene);
  try {
    check_laws_build(s);
    check_task_efforts(s);
    extend_for_pump_pacing(s);
  } catch (const SettingsError& e) {
    top.rethrow_placed(e);
  }
  s.effective = top.effective();
  return s;
}

FirmwareSettings read_firmware_settings(const settings::Document& scene) {
  settings::SectionReader top(scene);
  return read_firmware_settings(scene, read_scene_machine(top, scene));
}

FirmwareImageSettings image_settings(const FirmwareSettings& settings, const FirmwareNodeConfig& node, double duration) {
  FirmwareImageSettings image;
  image.scene = settings.name;
  image.machine = settings.machine;
  image.task = settings.task;
  image.node = node;
  image.cycles = static_cast<std::int64_t>(std::llround((duration > 0 ? duration : settings.duration) / node.controller.period));
  return image;
}

FirmwareSettings load_firmware_settings(const std::string& path) {
  return read_firmware_settings(settings::Document::load(path));
}

}  // namespace exc::app
