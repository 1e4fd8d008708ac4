#pragma once
// The keys of the plant's sections of a scene file (soil, initial_state, actuators, integrator,
// sensors, checks), listed once where the firmware can read them: the firmware links no plant code,
// yet a misspelt key in those sections is named by whichever program reads the scene, with the key
// it nearly spells. The plant's reader (sim_plant/scene.cpp) declares the same keys as it reads their
// values; the test `plant/the plant's scene reader declares exactly the shared list of its keys`
// holds the two together. Start-up code on the host: allocates, throws SettingsError.
#include <string>
#include <vector>

#include "settings/document.hpp"

namespace exc {

struct SceneSectionKeys {
  std::string section;            // one of kPlantSceneSections
  std::vector<std::string> keys;  // every key the plant's reader of that section declares
};

// One entry for each of kPlantSceneSections, in its order.
const std::vector<SceneSectionKeys>& plant_scene_keys();

// Refuses, at its line and column, a key of a plant's section that no reader declares ("soil.presett:
// unknown key; did you mean preset? allowed keys: ..."), and a plant's section that is no mapping.
// Values are not read: their ranges are the plant's to check.
void check_plant_scene_keys(const settings::Document& scene);

}  // namespace exc
