#pragma once
// Reading the scene's `controller:` section into a ControllerConfig (controller_config.hpp) with the
// settings reader: every field's unit and range declared once, then the cross-field rules. Errors
// (SettingsError) name the file, the line and column, the field and the allowed range. Start-up code
// on the host: allocates, throws.
#include "control/controller_config.hpp"
#include "settings/document.hpp"
#include "settings/section_reader.hpp"

namespace exc::control {

// Reads the `controller:` section into c (a field the section does not give keeps c's value, or the
// value derive_defaults derives for it on `nominal`; either is range-checked like a given one and
// recorded), then the cross-field rules (min < initial < max, Hurwitz gains, ...).
void read_controller_config(settings::SectionReader& controller, ControllerConfig& c, const Machine& nominal);
// The `controller:` section of a parsed scene file (absent: the defaults), the rest of the file left to
// its readers: a sweep's case that changes only controller settings reads them again so.
ControllerConfig read_controller_config(const settings::Document& scene, const Machine& nominal);

}  // namespace exc::control
