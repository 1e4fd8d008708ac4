#pragma once
// A scene file (YAML, schema in docs/scene-schema.md): machine, terrain and soil, initial state,
// actuator fidelity, integrator and step, duration, sensors, checks; plus the firmware's
// 'controller' and 'task' sections, which the plant keeps as text and leaves to the firmware.
// Loading validates every field; an error names the file, the field and the allowed values.
#include <stdexcept>
#include <string>

#include "model/machine.hpp"
#include "sim_plant/actuators.hpp"
#include "sim_plant/integrators.hpp"
#include "sim_plant/plant_checks.hpp"
#include "sim_plant/sensors.hpp"
#include "sim_plant/soil.hpp"

namespace exc::plant {

class SceneError : public std::runtime_error {
 public:
  SceneError(std::string file, std::string field, std::string reason);
  const std::string& file() const { return file_; }
  const std::string& field() const { return field_; }
  const std::string& reason() const { return reason_; }

 private:
  std::string file_, field_, reason_;
};

struct Scene {
  std::string file;         // the scene file ("<string>" when loaded from text)
  std::string name, description;
  std::string machine_file; // resolved path, empty for the built-in reference machine
  Machine machine;
  Terrain terrain;
  SoilPreset soil_preset = SoilPreset::none;  // 'none' also when given explicitly
  SoilParameters soil;
  Vec4 q_a0 = Vec4::Zero(), qd_a0 = Vec4::Zero();
  ActuatorParameters actuators;
  IntegratorSettings integrator;
  double cycle = 1e-3;      // s, one plant step (the SYNC period); integrator.step divides it
  double duration = 10.0;   // s
  SensorParameters sensors;
  CheckSettings checks;
  bool has_controller = false, has_task = false;
  std::string text;         // the whole file, for the firmware's own parser of controller/task
};

// Reads and validates a scene file. Throws SceneError (MachineError from the machine file is
// rethrown as a SceneError naming the 'machine' field and the machine file's message).
Scene load_scene(const std::string& path);
// Same from text; relative machine paths resolve against 'base_directory'.
Scene load_scene_from_string(const std::string& yaml, const std::string& file_for_errors,
                             const std::string& base_directory = ".");

}  // namespace exc::plant
