// The firmware's own loader of a scene file: its sections read, the plant's left alone, typos refused.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <string>

#include "app/firmware_settings.hpp"

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
