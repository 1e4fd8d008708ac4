// The firmware's own loader of a scene file: its sections read, the plant's left alone, typos refused.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "app/firmware_settings.hpp"
#include "control/effort_feasibility.hpp"
#include "scenes.hpp"

using namespace exc;

namespace {

const std::string kDig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";

std::string error_of(const std::string& yaml) {
  try {
    app::parse_firmware_settings(YAML::Load(yaml), "scene.yaml", ".");
  } catch (const control::ConfigError& e) {
    return e.field() + " | " + e.reason();
  }
  return "no error";
}

const char* const kTask = R"(
task:
  type: joint_waypoints
  waypoints:
    - {t: 0.0, q: [0.0, 2.30, 2.60, 1.95]}
    - {t: 2.0, q: [0.1, 2.35, 2.65, 1.90]}
)";

}  // namespace

TEST_CASE("firmware/settings read the shipped dig scene's firmware sections as written in the file") {
  const app::FirmwareSettings s = app::load_firmware_settings(kDig);
  CHECK(s.name == "dig");
  CHECK(s.task.type == control::TaskType::dig);
  CHECK(s.task.path.size() == 6);           // six tip poses in the file
  CHECK(s.task.end_time() == doctest::Approx(10.0));
  CHECK(s.controller.actuator_lag == doctest::Approx(0.02));
  CHECK(s.duration == doctest::Approx(10.0));
  CHECK(s.terrain_height == doctest::Approx(0.0));
  CHECK(s.machine_file.empty());  // no 'machine:' key: the built-in reference machine
  CHECK(s.machine.bodies.size() == reference_machine().bodies.size());
}

TEST_CASE("firmware/settings accept the plant's sections without reading them and refuse unknown ones") {
  const std::string plant_sections =
      "name: x\nduration: 2\nsoil: {preset: loam}\nactuators: {fidelity: limited, lag: 0.02}\n"
      "integrator: {method: rk4}\nsensors: {seed: 3}\ninitial_state: {q_a: [0, 2.4, 2.5, 1.9]}\nchecks: {}\n";
  CHECK(error_of(plant_sections + kTask) == "no error");
  CHECK(error_of("name: x\nduration: 2\nsoyl: {preset: loam}\n" + std::string(kTask))
            .rfind("soyl | unknown key (allowed: ", 0) == 0);
  CHECK(error_of("name: x\nduration: 2\n") == "task | missing: the firmware needs a task");
  CHECK(error_of("name: x\n" + std::string(kTask)) .rfind("duration | missing", 0) == 0);
  CHECK(error_of("name: x\nduration: 2\nterrain: {height: 50}\n" + std::string(kTask)).rfind("terrain.height | ", 0) == 0);
  CHECK(error_of("name: x\nduration: 2\ncontroller: {kp: 3}\n" + std::string(kTask)).rfind("controller.kp | ", 0) == 0);
  CHECK(error_of("name: x\nduration: 2\nmachine: /nonexistent.yaml\n" + std::string(kTask)).rfind("machine | the machine file does not load", 0) == 0);
}

TEST_CASE("firmware/settings name the file when it is missing or not YAML") {
  try {
    app::load_firmware_settings("/nonexistent/scene.yaml");
    FAIL("no error");
  } catch (const control::ConfigError& e) {
    CHECK(e.file() == "/nonexistent/scene.yaml");
    CHECK(e.reason() == "cannot open the file");
  }
}

namespace {

// Issue 16's scene: a 2 rad swing in 2.5 s, inside the swing's speed limit but not its torque.
std::string fast_swing_scene(const std::string& efforts) {
  std::string task = exc::control::sim::kFastSwingTask;
  const std::string type = "  type: joint_waypoints\n";
  task.insert(task.find(type) + type.size(), efforts);
  return "name: fast_swing\nduration: 3\n" + task;
}

}  // namespace

TEST_CASE("firmware/settings refuse a task the actuators cannot drive, naming the place, the joint, the torque and the timing that fits") {
  const std::string e = error_of(fast_swing_scene(""));
  MESSAGE(e);
  CHECK(e.rfind("task.waypoints | task.waypoints[0] -> task.waypoints[1] at t = ", 0) == 0);
  CHECK(e.find("the swing needs ") != std::string::npos);
  CHECK(e.find("65.0 kN m") != std::string::npos);
  CHECK(e.find("it fits with the timing scaled by 2.2") != std::string::npos);
  CHECK(e.find("or set task.efforts.fit_timing: true") != std::string::npos);
}

TEST_CASE("firmware/settings fit a task's timing when asked, and say by how much, check: false forces it as written") {
  const app::FirmwareSettings fit =
      app::parse_firmware_settings(YAML::Load(fast_swing_scene("  efforts: {fit_timing: true}\n")), "scene.yaml", ".");
  MESSAGE("timing scaled by " << fit.task.timing_scale);
  CHECK(fit.task.timing_scale > 2.0);
  CHECK(fit.task.timing_scale < 2.5);
  CHECK(fit.task.end_time() == doctest::Approx(2.5 * fit.task.timing_scale));
  CHECK(fit.task.waypoint_times.back() == doctest::Approx(2.5 * fit.task.timing_scale));
  const Model model = build_model(fit.machine);
  CHECK(control::check_effort_feasibility(model, fit.task.trajectory).ok);

  const app::FirmwareSettings forced =
      app::parse_firmware_settings(YAML::Load(fast_swing_scene("  efforts: {check: false}\n")), "scene.yaml", ".");
  CHECK(forced.task.timing_scale == 1.0);
  CHECK(forced.task.end_time() == doctest::Approx(2.5));
  CHECK(error_of(fast_swing_scene("  efforts: {check: maybe}\n")) == "task.efforts.check | must be true or false");
  CHECK(error_of(fast_swing_scene("  efforts: {soil_margin: 2}\n")).rfind("task.efforts.soil_margin | ", 0) == 0);
}

TEST_CASE("firmware/settings accept a run of a working shift (duration 28800 s) and refuse one second more, naming the field and the range") {
  CHECK(error_of("name: x\nduration: 28800\n" + std::string(kTask)) == "no error");
  CHECK(error_of("name: x\nduration: 28801\n" + std::string(kTask)) ==
        "duration | 28801 s outside the allowed range 0.001 .. 28800");
}
