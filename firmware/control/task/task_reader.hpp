#pragma once
// Reading the scene's `task:` section into a Task (task.hpp) with the settings reader, the trajectory
// built and checked against the machine's limits (dig_path.hpp, work_cycle.hpp). Start-up code on
// the host: allocates, throws SettingsError.
#include "control/task/task.hpp"
#include "model/machine.hpp"
#include "settings/document.hpp"
#include "settings/section_reader.hpp"

namespace exc::control {

// Reads the `task:` section (required: an absent one is an error).
Task read_task(settings::SectionReader& task, const Machine& machine, const TrajectoryCheckOptions& options = {});
// The `task:` section of a parsed scene file (the rest of the file left to its readers).
Task read_task(const settings::Document& scene, const Machine& machine, const TrajectoryCheckOptions& options = {});

}  // namespace exc::control
