#pragma once
// A scene as a process reads it: the scene file and the machine file it names, each opened and
// parsed once, and what both sides read from them (SceneBundle). A sweep's case reads them again
// with some settings set (SceneChanges): copies of the files' trees changed by setting path and read
// by the same readers, so a value a case sets is validated as the same value in the file would be,
// and its errors name the setting and its range.
#include <optional>
#include <string>

#include <yaml-cpp/yaml.h>

#include "app/firmware_settings.hpp"
#include "model/scene_common_reader.hpp"
#include "settings/document.hpp"
#include "sim_plant/scene.hpp"

namespace exc::sim {

// A scene as both sides read it: the plant's sections (true machine, soil, actuators, ...) and the
// firmware's (nominal machine, controller, task, terrain height, duration).
struct SceneBundle {
  std::string name;
  plant::Scene scene;
  app::FirmwareSettings firmware;
  // The scene's effective configuration: both sides' sections, every default filled in, the machine
  // as an absolute path when the scene names one. Loads back to the same run (settings::emit).
  YAML::Node effective;
};

struct SceneSource {
  settings::Document scene;  // the scene file as parsed
  SceneMachine machine;      // the machine file it names (or the built-in machine), as parsed and read
  SceneBundle nominal;       // what both sides read from them
  // A setting's declaration (type, count, range, unit) as its reader declared it, by its path (as
  // SceneChanges takes it): the scene's ("sensors.latency_cycles") or, after "machine." or
  // "firmware.machine.", the machine file's; null when this scene's readers read no such field.
  const settings::Declaration* declaration(const std::string& path) const;
};

// Loads both sides of one scene file, the scene and its machine file each opened and parsed once
// (validated; errors name the file, the line and column and the field).
SceneSource load_scene_source(const std::string& path);
SceneBundle load_scene_bundle(const std::string& path);

// Settings of a scene changed by path (a sweep's case), on copies of the nominal files' trees:
//   "sensors.latency_cycles", "soil", ...    the scene file's keys (read by the side that reads them)
//   "machine.hydraulics.bulk_modulus"        the plant's machine (the true one; the firmware keeps its own)
//   "firmware.machine.bodies.boom.mass"      the firmware's model of the machine (the plant keeps the true one)
// The firmware reads its sections against the scene's machine file (its task is checked against it as
// the file is), then runs with its model changed.
class SceneChanges {
 public:
  explicit SceneChanges(const SceneSource& source) : source_(source) {}
  const SceneSource& source() const { return source_; }
  void set(const std::string& path, const YAML::Node& value);
  // The setting's value as the nominal scene reads it (a scene path: the effective configuration, every
  // default filled in; a machine path: the machine file's); throws std::invalid_argument when absent.
  YAML::Node nominal(const std::string& path) const;
  // A scene setting as this case has it so far (a copy): what a knob set before wrote, else the
  // nominal's. Two derived knobs that change different fields of one setting (the task path's times
  // and its heights) compose through it, in either order.
  YAML::Node current(const std::string& path) const;
  // The scene with the changes, read again by the readers of what changed (SettingsError when a
  // reader refuses a value).
  SceneBundle read() const;

 private:
  const SceneSource& source_;
  std::optional<YAML::Node> scene_, plant_machine_, firmware_machine_;  // copies, made at the first change of each
  bool plant_sections_ = false, firmware_sections_ = false, controller_ = false;  // what the scene changes concern
};

// A number or a list of numbers times `factor`, as the settings reader writes numbers.
YAML::Node scaled(const YAML::Node& value, double factor);

}  // namespace exc::sim
