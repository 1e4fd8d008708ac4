#pragma once
// The plant's reading of a scene file (YAML, schema in docs/scene-schema.md): the keys both sides
// read (model/scene_common.hpp: name, machine, terrain, duration) and the simulated machine's own
// sections: soil, initial state, actuator fidelity, integrator and step, sensors, checks. The
// firmware's sections (controller, task) are named and left to the firmware's reader. Every field
// is declared once, with the settings reader; an error (SettingsError) names the file, the line and
// column, the field and the allowed values.
#include <string>

#include <yaml-cpp/yaml.h>

#include "model/machine.hpp"
#include "model/scene_common_reader.hpp"
#include "settings/document.hpp"
#include "sim_plant/actuators.hpp"
#include "sim_plant/integrators.hpp"
#include "sim_plant/plant_checks.hpp"
#include "sim_plant/sensors.hpp"
#include "sim_plant/soil.hpp"

namespace exc::plant {

struct Scene {
  std::string file;         // the scene file ("<string>" when loaded from text)
  std::string name, description;
  std::string machine_file; // absolute path, empty for the built-in reference machine
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
  // The plant's sections as read, every default filled in (the effective configuration).
  YAML::Node effective;
};

// Reads the plant's sections of a parsed scene file (and the machine file it names).
Scene read_scene(const settings::Document& scene);
// The same against its machine already read (read_scene_machine: the file loaded once for both sides).
Scene read_scene(const settings::Document& scene, const SceneMachine& machine);
// Reads and validates a scene file (opened and parsed once).
Scene load_scene(const std::string& path);

}  // namespace exc::plant
