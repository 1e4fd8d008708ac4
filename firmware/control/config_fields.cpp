#include "control/config_fields.hpp"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <sstream>

namespace exc::control {

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

double read_number(const YAML::Node& n, const std::string& file, const std::string& field, double lo, double hi,
                   const std::string& unit) {
  const std::string range = format_number(lo) + " .. " + format_number(hi) + (unit.empty() ? "" : " " + unit);
  if (!n.IsDefined() || n.IsNull()) throw ConfigError(file, field, "missing (a number in " + range + ")");
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    throw ConfigError(file, field, "not a number (allowed: " + range + ")");
  }
  if (!std::isfinite(v) || v < lo || v > hi)
    throw ConfigError(file, field, format_number(v) + (unit.empty() ? "" : " " + unit) + " outside the allowed range " +
                                       format_number(lo) + " .. " + format_number(hi));
  return v;
}

void reject_unknown_keys(const YAML::Node& n, const std::string& file, const std::string& field,
                         const std::set<std::string>& allowed) {
  if (!n.IsMap()) throw ConfigError(file, field, "must be a mapping");
  for (const auto& kv : n) {
    const std::string key = kv.first.as<std::string>();
    if (!allowed.count(key)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      throw ConfigError(file, field.empty() ? key : field + "." + key, "unknown key (allowed: " + list + ")");
    }
  }
}

YAML::Node load_yaml_file(const std::string& path) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::BadFile&) {
    throw ConfigError(path, "", "cannot open the file");
  } catch (const YAML::Exception& e) {
    throw ConfigError(path, "", std::string("not valid YAML: ") + e.what());
  }
}

}  // namespace exc::control
