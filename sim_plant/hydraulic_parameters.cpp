// HydraulicParameters::validate: every field against its documented range.
#include <cmath>
#include <cstdio>
#include <string>

#include "sim_plant/hydraulics.hpp"

namespace exc::plant {

namespace {

// "" if lo <= v <= hi, else "hydraulic.<name> is <v> <unit>; allowed range [lo, hi] <unit>".
std::string check(const char* name, double v, double lo, double hi, const char* unit) {
  if (std::isfinite(v) && v >= lo && v <= hi) return "";
  char b[200];
  std::snprintf(b, sizeof b, "hydraulic.%s is %g %s; allowed range [%g, %g] %s", name, v, unit, lo, hi, unit);
  return b;
}

}  // namespace

std::string HydraulicParameters::validate() const {
  std::string e;
  const auto first = [&e](const std::string& m) {
    if (e.empty()) e = m;
  };
  first(check("pump_flow", pump_flow, 1e-4, 0.05, "m^3/s"));
  for (int i = 0; i < 4; ++i)
    if (pump_of[i] != 0 && pump_of[i] != 1)
      first(check(("pump_of[" + std::to_string(i) + "]").c_str(), pump_of[i], 0, 1, "(pump index)"));
  first(check("load_sensing_margin", load_sensing_margin, 0.3e6, 5e6, "Pa"));
  first(check("main_relief_pressure", main_relief_pressure, 5e6, 60e6, "Pa"));
  first(check("port_relief_pressure", port_relief_pressure, 5e6, 60e6, "Pa"));
  first(check("swing_relief_pressure", swing_relief_pressure, 5e6, 60e6, "Pa"));
  first(check("relief_override", relief_override, 1e4, 10e6, "Pa"));
  first(check("makeup_pressure_drop", makeup_pressure_drop, 1e4, 2e6, "Pa"));
  first(check("vapour_pressure", vapour_pressure, -0.1e6, 0.1e6, "Pa"));
  first(check("pilot_full_stroke", pilot_full_stroke, 1e6, 10e6, "Pa"));
  for (int i = 0; i < 4; ++i) {
    first(check(("dead_zone_extend[" + std::to_string(i) + "]").c_str(), dead_zone_extend[i], 0, 0.9, "(of the stroke)"));
    first(check(("dead_zone_retract[" + std::to_string(i) + "]").c_str(), dead_zone_retract[i], 0, 0.9, "(of the stroke)"));
  }
  first(check("pressure_check_margin", pressure_check_margin, 0, 50e6, "Pa"));
  return e;
}

}  // namespace exc::plant
