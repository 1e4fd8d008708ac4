// Scenes as a process reads them (each file once) and as a sweep's case reads them again with
// settings changed: copies of the files' trees, read by the same readers.
#include "harness/scene_source.hpp"

#include <algorithm>
#include <stdexcept>
#include <string_view>

#include "control/controller_config.hpp"
#include "settings/section_reader.hpp"
#include "model/machine_reader.hpp"
#include "control/controller_config_reader.hpp"

namespace exc::sim {
namespace {

constexpr std::string_view kPlantMachine = "machine.";
constexpr std::string_view kFirmwareMachine = "firmware.machine.";

bool starts_with(const std::string& s, std::string_view prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

// The node at a dotted path ("controller.valves.position_gain"); undefined when absent.
YAML::Node node_at(const YAML::Node& root, const std::string& path) {
  YAML::Node node;
  node.reset(root);
  for (std::size_t start = 0;;) {
    const std::size_t end = path.find('.', start);
    if (!node.IsMap()) return YAML::Node(YAML::NodeType::Undefined);
    const YAML::Node& map = node;
    const YAML::Node child = map[path.substr(start, end == std::string::npos ? end : end - start)];
    if (!child.IsDefined()) return child;
    node.reset(child);  // reset rebinds the handle; assigning would overwrite the tree's node
    if (end == std::string::npos) return node;
    start = end + 1;
  }
}

// Sets the value at a dotted path in `tree` (a copy of `original`, made on the first call), making
// the mappings on the way.
void set_at(std::optional<YAML::Node>& tree, const YAML::Node& original, const std::string& path, const YAML::Node& value) {
  if (!tree) tree = YAML::Clone(original);
  YAML::Node node;
  node.reset(*tree);
  std::size_t start = 0;
  for (std::size_t end = path.find('.'); end != std::string::npos; start = end + 1, end = path.find('.', start)) {
    const std::string key = path.substr(start, end - start);
    if (!node[key].IsMap()) node[key] = YAML::Node(YAML::NodeType::Map);
    const YAML::Node child = node[key];
    node.reset(child);
  }
  node[path.substr(start)] = value;
}

// The firmware's commands must be of the kind the machine takes: a hydraulic machine takes pilot
// pressures (command_interface: valve), force-actuated ones take efforts. A run of the two mismatched
// could only fail at its first command (or never track), so the file is refused at load, placed as
// the settings reader places any error (at the key, or at its section when the key is absent).
void check_command_fits(const settings::Document& scene, const SceneBundle& b) {
  const bool valves = plant::fidelity_of(b.scene.actuators).takes_valves();
  const control::CommandInterface wanted = valves ? control::CommandInterface::valve : control::CommandInterface::effort;
  const control::CommandInterface given = b.firmware.controller.command_interface;
  if (given == wanted) return;
  settings::SectionReader top(scene);
  const settings::SectionReader controller = top.section("controller", "the control law's settings");
  controller.fail("command_interface",
                  std::string("is ") + control::kCommandInterfaces.name_of(given) +
                      (controller.has("command_interface") ? "" : " (not given: the default)") + " but actuators.fidelity is " +
                      b.scene.actuators.fidelity + ", which takes " +
                      (valves ? "valve (pilot pressure) commands" : "efforts") +
                      "; set command_interface: " + control::kCommandInterfaces.name_of(wanted));
}

// What follows either side's reading: the plant runs as long as the firmware (fit_timing may stretch the task).
void finish(SceneBundle& b) {
  b.name = b.scene.name;
  b.scene.duration = b.firmware.duration;  // longer when task.efforts.fit_timing stretched the path
}

}  // namespace

const settings::Declaration* SceneSource::declaration(const std::string& path) const {
  if (starts_with(path, kPlantMachine)) return machine.document.declaration(path.substr(kPlantMachine.size()));
  if (starts_with(path, kFirmwareMachine)) return machine.document.declaration(path.substr(kFirmwareMachine.size()));
  return scene.declaration(path);
}

SceneSource load_scene_source(const std::string& path) {
  SceneSource s;
  s.scene = settings::Document::load(path);
  settings::SectionReader top(s.scene);
  s.machine = read_scene_machine(top, s.scene);
  // Each side reads its own sections from the same document, against the same machine.
  SceneBundle& b = s.nominal;
  b.scene = plant::read_scene(s.scene, s.machine);
  b.firmware = app::read_firmware_settings(s.scene, s.machine);
  check_command_fits(s.scene, b);
  finish(b);
  b.effective = YAML::Clone(b.scene.effective);
  settings::merge_effective(b.effective, b.firmware.effective);
  return s;
}

SceneBundle load_scene_bundle(const std::string& path) { return load_scene_source(path).nominal; }

void SceneChanges::set(const std::string& path, const YAML::Node& value) {
  const SceneMachine& m = source_.machine;
  if (starts_with(path, kFirmwareMachine)) {
    set_at(firmware_machine_, m.document.root(), path.substr(kFirmwareMachine.size()), value);
  } else if (starts_with(path, kPlantMachine)) {
    set_at(plant_machine_, m.document.root(), path.substr(kPlantMachine.size()), value);
  } else {
    const std::string section = path.substr(0, path.find('.'));
    if (section == "machine") throw std::invalid_argument("the scene's machine file cannot be changed: set its settings (machine.<path>)");
    set_at(scene_, source_.scene.root(), path, value);
    const auto in = [&section](const std::vector<std::string>& keys) {
      return std::find(keys.begin(), keys.end(), section) != keys.end();
    };
    // The sections one side reads concern that side; the shared keys (terrain, duration, ...) both.
    controller_ = controller_ || section == "controller";
    plant_sections_ = plant_sections_ || !in(kFirmwareSceneSections);
    firmware_sections_ = firmware_sections_ || (!in(kPlantSceneSections) && section != "controller");
  }
}

YAML::Node SceneChanges::nominal(const std::string& path) const {
  const bool machine = starts_with(path, kPlantMachine) || starts_with(path, kFirmwareMachine);
  const std::string rest = path.substr(!machine ? 0 : starts_with(path, kPlantMachine) ? kPlantMachine.size() : kFirmwareMachine.size());
  const YAML::Node n = node_at(machine ? source_.machine.document.root() : source_.nominal.effective, rest);
  if (!n.IsDefined())
    throw std::invalid_argument(path + ": " + (machine ? source_.machine.document.file() : source_.scene.file()) + " has no such setting");
  return n;
}

YAML::Node SceneChanges::current(const std::string& path) const {
  if (scene_ && !starts_with(path, kPlantMachine) && !starts_with(path, kFirmwareMachine)) {
    const YAML::Node n = node_at(*scene_, path);
    if (n.IsDefined()) return YAML::Clone(n);
  }
  return YAML::Clone(nominal(path));
}

SceneBundle SceneChanges::read() const {
  if (!scene_ && !plant_machine_ && !firmware_machine_) return source_.nominal;
  const settings::Document scene = scene_ ? source_.scene.with_root(*scene_) : source_.scene;
  const SceneMachine& nominal_machine = source_.machine;
  // Each member assigned once, into a new bundle: assigning a YAML node that shares the nominal's tree
  // (Scene::effective) would overwrite that tree.
  SceneBundle b;
  // The machine file's tree with a side's values set, read as that side's machine.
  const auto changed_machine = [&nominal_machine](const YAML::Node& tree) {
    SceneMachine m{nominal_machine.file, nominal_machine.document.with_root(tree), {}};
    m.machine = read_machine(m.document);
    return m;
  };
  if (plant_machine_) {
    b.scene = plant::read_scene(scene, changed_machine(*plant_machine_));
  } else {
    b.scene = plant_sections_ ? plant::read_scene(scene, nominal_machine) : source_.nominal.scene;
  }
  // The firmware's sections read against its own machine (the file's, or the file's with the case's
  // firmware.machine.* values), so what the controller derives from the machine at load (the valve
  // stage's spool lead and force-loop time constants) follows the firmware's model, not the file's;
  // the controller alone when only it changed (the task's effort check is the costly part of the reading).
  if (firmware_machine_) {
    b.firmware = app::read_firmware_settings(scene, changed_machine(*firmware_machine_));
  } else {
    b.firmware = firmware_sections_ ? app::read_firmware_settings(scene, nominal_machine) : source_.nominal.firmware;
    if (controller_ && !firmware_sections_) b.firmware.controller = control::read_controller_config(scene, nominal_machine.machine);
  }
  check_command_fits(scene, b);
  finish(b);  // its effective configuration left empty: a case's is its scene's with the values it sets
  return b;
}

YAML::Node scaled(const YAML::Node& value, double factor) {
  if (value.IsScalar()) return YAML::Node(settings::format_number(value.as<double>() * factor));
  YAML::Node list(YAML::NodeType::Sequence);
  list.SetStyle(YAML::EmitterStyle::Flow);
  for (const YAML::Node& element : value) list.push_back(scaled(element, factor));
  return list;
}

}  // namespace exc::sim
