#pragma once
// The keys of a scene file that both sides read, declared once: the scene's name and description,
// the machine file (the plant's true machine, the firmware's nominal one: the same file), the ground
// (flat height or a profile) and the run's duration. Each side then reads its own sections and names
// the other's, so a misspelt section is refused by both:
//   the firmware  controller, task                 (firmware/app/firmware_settings)
//   the plant     soil, initial_state, actuators, integrator, sensors, checks   (sim_plant/scene)
// Start-up code: allocates, throws SettingsError.
#include <string>
#include <vector>

#include "model/machine.hpp"
#include "model/terrain.hpp"
#include "settings/section_reader.hpp"

namespace exc {

inline const std::vector<std::string> kFirmwareSceneSections = {"controller", "task"};
inline const std::vector<std::string> kPlantSceneSections = {"soil",       "initial_state", "actuators",
                                                             "integrator", "sensors",       "checks"};

// A run's duration (s): the scene's `duration` and the programs' --duration overrides.
inline constexpr settings::Bounds kRunDurationBounds{1e-3, 28800};

// The machine a scene names (its `machine` key), opened and parsed once: the file resolved against
// the scene's directory, or the built-in machine when the scene names none. Both sides read their
// sections against it, so a scene's machine file is loaded once however many read the scene.
struct SceneMachine {
  std::string file;             // absolute path of the machine file, empty for the built-in reference machine
  settings::Document document;  // the file as parsed (the built-in machine's text for the built-in one)
  Machine machine;
};
// Reads the scene's `machine` key (an error in the machine file is placed at the key).
SceneMachine read_scene_machine(settings::SectionReader& top, const settings::Document& scene);

struct SceneCommon {
  std::string name, description;
  std::string machine_file;  // absolute path of the machine file, empty for the built-in reference machine
  Machine machine;
  // The ground: flat at the machine's terrain.flat_height by default, or the scene's height or profile.
  Terrain terrain;
  double duration = 10;                // s
};

// Reads the shared keys from the scene's top level (their values recorded in its effective tree;
// the machine as an absolute path when the scene names one), the machine being `machine`.
SceneCommon read_scene_common(settings::SectionReader& top, const SceneMachine& machine);

}  // namespace exc
