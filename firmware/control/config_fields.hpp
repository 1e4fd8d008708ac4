#pragma once
// Reading the firmware's scene sections field by field (`controller:`, `task:`): numbers checked
// against their allowed range, mappings checked for unknown keys, each error a ConfigError naming
// the file, the dotted field and the range. Start-up code: allocates, throws.
#include <set>
#include <string>

#include "control/config_error.hpp"

#include <yaml-cpp/yaml.h>

namespace exc::control {

// The YAML document of a file; ConfigError "cannot open the file" or "not valid YAML: ..." naming it.
YAML::Node load_yaml_file(const std::string& path);

// A number as errors print it (shortest of %g style, e.g. 1e+06, 0.02).
std::string format_number(double v);

// The number at n, finite and within lo .. hi ('unit', if given, follows the value in messages).
// A missing node is an error too ("missing (a number in lo .. hi unit)").
double read_number(const YAML::Node& n, const std::string& file, const std::string& field, double lo, double hi,
                   const std::string& unit = "");

// n must be a mapping whose keys are all in 'allowed' ("field.key: unknown key (allowed: ...)").
void reject_unknown_keys(const YAML::Node& n, const std::string& file, const std::string& field,
                         const std::set<std::string>& allowed);

}  // namespace exc::control
