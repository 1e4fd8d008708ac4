#pragma once
// The firmware's own reading of a scene file: the sections a controller on a real machine is given
// (its nominal machine, `controller:`, `task:`, the site's terrain height and the run's duration).
// The simulated machine's sections (soil, actuators, integrator, sensors, initial state, checks)
// belong to the plant, which reads them with its own loader; the firmware checks that every
// top-level key is a known section and every key of the plant's sections a known key
// (model/plant_scene_keys.hpp), so a typo is an error on both sides. Nothing here links plant code. Start-up code: allocates, throws SettingsError naming file, line, column, field and range.
#include <string>

#include <yaml-cpp/yaml.h>

#include "app/firmware_node_config.hpp"
#include "app/settings_blob.hpp"
#include "control/controller_config.hpp"
#include "control/task/task.hpp"
#include "model/machine.hpp"
#include "model/terrain.hpp"
#include "model/scene_common_reader.hpp"
#include "settings/document.hpp"

namespace exc::app {

struct FirmwareSettings {
  std::string file;          // the scene file
  std::string name;          // scene name
  std::string machine_file;  // absolute path of the nominal machine, empty for the built-in one
  Machine machine;           // the controller's model of the machine (nominal parameters)
  control::ControllerConfig controller;
  control::Task task;
  Terrain terrain;  // the site map (the scene's terrain: flat or a profile) the soil-contact estimate may use
  // s, how long the run lasts: the scene's `duration`, unless task.efforts.fit_timing stretched a
  // path the scene's duration covered (then longer by the time the path grew)
  double duration = 10;
  double scene_duration = 10;  // s, the scene's `duration` as written
  // The firmware's sections as read, every default filled in (the effective configuration).
  YAML::Node effective;
};

// Opens and parses the file once.
FirmwareSettings load_firmware_settings(const std::string& path);
// From an already parsed scene file (the one the plant's reader reads too).
FirmwareSettings read_firmware_settings(const settings::Document& scene);
// The same against its machine already read (read_scene_machine: the file loaded once for both sides).
FirmwareSettings read_firmware_settings(const settings::Document& scene, const SceneMachine& machine);

// What the firmware's image runs (settings_blob.hpp): these settings, the node built with `node`, for
// `duration` s (0: the run's duration) in whole periods of node.controller.period, rounded.
FirmwareImageSettings image_settings(const FirmwareSettings& settings, const FirmwareNodeConfig& node, double duration = 0);

}  // namespace exc::app
