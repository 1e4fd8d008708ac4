#pragma once
// The keys of a scene file that both sides read, declared once: the scene's name and description,
// the machine file (the plant's true machine, the firmware's nominal one: the same file), the ground
// (flat height or a profile) and the run's duration. Each side then reads its own sections and names
// the other's, so a misspelt section is refused by both:
//   the firmware  controller, task                 (firmware/app/firmware_settings)
//   the plant     soil, initial_state, actuators, integrator, sensors, checks   (sim_plant/scene)
// What they are; scene_common_reader.hpp reads them.
#include <string>
#include <vector>

#include "model/machine.hpp"
#include "model/terrain.hpp"
#include "settings/declaration.hpp"

namespace exc {

inline const std::vector<std::string> kFirmwareSceneSections = {"controller", "task"};
inline const std::vector<std::string> kPlantSceneSections = {"soil",       "initial_state", "actuators",
                                                             "integrator", "sensors",       "checks"};

// A run's duration (s): the scene's `duration` and the programs' --duration overrides.
inline constexpr settings::Bounds kRunDurationBounds{1e-3, 28800};

struct SceneCommon {
  std::string name, description;
  std::string machine_file;  // absolute path of the machine file, empty for the built-in reference machine
  Machine machine;
  // The ground: flat at the machine's terrain.flat_height by default, or the scene's height or profile.
  Terrain terrain;
  double duration = 10;                // s
};

}  // namespace exc
