#pragma once
// A sweep's knobs: what a case sets. A knob names a setting by its path: a key of the scene
// ("sensors.latency_cycles", "controller.valves.force_time_constant"), of the plant's machine file
// ("machine.hydraulics.bulk_modulus") or of the firmware's model of that machine
// ("firmware.machine.hydraulics.valve_time_constant"). It takes the setting's type, unit and range
// from the declaration of the reader that reads it; a case's value goes into a copy of the file's tree
// and is read by the scene's readers (harness/scene_source.hpp), so a value the scene's reader refuses
// is refused when the spec loads. Any numeric or enumerated setting is a knob without a line here.
//
// The tables below hold the named knobs, each declared once: a short name for a setting, or a derived
// knob (one value standing for several settings, with its own range, writing those settings from
// their nominal values; the readers then check what it wrote). Adding one is one line:
//   {"latency", "sensors.latency_cycles"},
//   {"soil_damping", nullptr, {0.1, 10}, "", "the soil's B x value", scale_soil_damping},
#include <string>
#include <vector>

#include "harness/scene_source.hpp"
#include "settings/declaration.hpp"
#include "sweep.hpp"

namespace exc::sim {

struct Knob {
  const char* name;
  const char* setting = nullptr;  // the setting's path it is a short name for; null: derived
  // A derived knob: the value's range, unit and meaning, and what it sets (null: no scene setting,
  // the run reads the value itself, as the open loop's profile.speed).
  settings::Bounds range{0, 0};
  const char* unit = "";
  const char* what = "";
  void (*apply)(SceneChanges& changes, const SweepValue& value) = nullptr;
  bool names = false;  // takes a name instead of a number
  // A derived knob: the settings it writes whole from the nominal scene's values (space-separated
  // paths), which a knob changing the same setting before it would see undone. Fields it changes from
  // the case's current values (SceneChanges::current) compose and are not listed.
  const char* writes = "";
};

// The named knobs of a run kind (docs/sweeps.md has a row for each; tests/sim checks them).
const std::vector<Knob>& named_knobs(SweepRun run);

// What a knob's values are, as a declaration: a derived knob's own, else its setting's as the scene's
// readers declared it (field: the setting's path). std::invalid_argument saying what a knob can be
// when `knob` is neither.
settings::Declaration knob_values(SweepRun run, const std::string& knob, const SceneSource& scene);

// The settings a knob writes whole (a setting's knob: its path): two knobs of one spec whose settings
// are the same or one inside the other would undo each other, and the spec is refused.
std::vector<std::string> knob_writes(SweepRun run, const std::string& knob);

// Puts one value of a knob into a case's changes.
void set_knob(SweepRun run, const std::string& knob, const SweepValue& value, SceneChanges& changes);

// The open loop's plant cycle for an integration step: the step itself above 1 ms, else 1 ms with
// substeps (excavator-bench's open-loop runs step the plant so).
double open_loop_cycle(double step);

}  // namespace exc::sim
