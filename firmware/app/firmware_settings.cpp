#include "app/firmware_settings.hpp"

#include <yaml-cpp/yaml.h>

#include "control/config_fields.hpp"

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
  s.duration = control::read_number(root["duration"], file, "duration", 1e-3, 3600, "s");
  s.controller = control::parse_controller_config(root["controller"], file);
  if (!root["task"]) throw ConfigError(file, "task", "missing: the firmware needs a task");
  s.task = control::parse_task(root["task"], file, s.machine);
  return s;
}

FirmwareSettings load_firmware_settings(const std::string& path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw control::ConfigError(path, "", "cannot open the file");
  } catch (const YAML::Exception& e) {
    throw control::ConfigError(path, "", std::string("not valid YAML: ") + e.what());
  }
  return parse_firmware_settings(root, path, directory_of(path));
}

}  // namespace exc::app
