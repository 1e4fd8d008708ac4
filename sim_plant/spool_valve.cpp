#include "sim_plant/spool_valve.hpp"

#include <algorithm>
#include <cmath>

namespace exc::plant {

double spool_target_from_opening(double opening) { return std::clamp(opening, -1.0, 1.0); }

double spool_target_from_pilots(double pilot_a, double pilot_b, double full_stroke_pressure) {
  return std::clamp((pilot_a - pilot_b) / full_stroke_pressure, -1.0, 1.0);
}

double spool_lag_gain(double time_constant, double dt) {
  return time_constant > 0 ? 1.0 - std::exp(-dt / time_constant) : 1.0;
}

double spool_lag(double spool, double target, double gain) { return spool + gain * (target - spool); }

double metering_opening(double spool, double dead_zone_extend, double dead_zone_retract) {
  const double d = spool >= 0 ? dead_zone_extend : dead_zone_retract;
  const double x = std::abs(spool);
  return x > d ? std::min(1.0, (x - d) / (1.0 - d)) : 0.0;
}

}  // namespace exc::plant
