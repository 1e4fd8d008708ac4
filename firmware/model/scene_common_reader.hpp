#pragma once
// Reading the keys of a scene file both sides read (scene_common.hpp) and the machine file the scene
// names, with the settings reader. Start-up code on the host: allocates, throws SettingsError.
#include <string>

#include "model/machine_reader.hpp"
#include "model/scene_common.hpp"
#include "settings/section_reader.hpp"

namespace exc {

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

// Reads the shared keys from the scene's top level (their values recorded in its effective tree;
// the machine as an absolute path when the scene names one), the machine being `machine`.
SceneCommon read_scene_common(settings::SectionReader& top, const SceneMachine& machine);

}  // namespace exc
