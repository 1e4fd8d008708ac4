#pragma once
// Reading a machine file (machines/reference-20t.yaml) into a Machine (machine.hpp) with the settings
// reader: every field validated; errors (SettingsError) name file, line, column, field and reason.
// Start-up code on the host: allocates, throws; the firmware's image gets its machine from the
// settings blob instead (app/settings_blob.hpp).
#include <string>

#include "model/machine.hpp"
#include "settings/document.hpp"
#include "settings/settings_error.hpp"

namespace exc {

// Reads and validates a machine file (read and parsed once). Throws SettingsError.
Machine load_machine(const std::string& path);
// The same from a parsed machine file (or a tree of it with values set: a sweep's case).
Machine read_machine(const settings::Document& machine_file);
// Same, from YAML text; 'file_for_errors' is what errors name as the file.
Machine load_machine_from_string(const std::string& yaml, const std::string& file_for_errors);
// The reference machine compiled into the binary (same numbers as machines/reference-20t.yaml).
Machine reference_machine();
// The built-in machine's file as it was compiled in (what a sweep's digest covers for scenes without
// a machine file).
const char* reference_machine_text();
// Checks hydraulics built or changed in C++ against the ranges the machine file's reader declares
// (SettingsError naming machine.source and the field, e.g. "hydraulics.pump_flow").
void validate_hydraulics(const Machine& machine);

}  // namespace exc
