// The defaults a nominal machine and a command interface imply (the reader starts from them; a bench
// switches a configuration's interface with them). Nothing here reads a file.
#include "control/controller_config.hpp"

#include <algorithm>

namespace exc::control {

ControllerConfig controller_defaults(const Machine& nominal) {
  ControllerConfig c;
  c.valves.force_time_constant = std::max(nominal.hydraulics.valve_time_constant, 0.005);
  c.valves.spool_lag_target = nominal.hydraulics.valve_time_constant / 3;
  c.plausibility.velocity_floor = kPlausibilityVelocityShare * nominal.speed_max();
  c.plausibility.frozen_speed = kFrozenSpeedShare * nominal.speed_max();
  return c;
}

Vec4 default_tracking_error_limit(CommandInterface interface) {
  if (interface != CommandInterface::valve) return ControllerConfig{}.tracking_error_limit;
  Vec4 limit;
  for (int j = 0; j < 4; ++j) limit[j] = kTrackingLimitMultiple * kValveMachineReach[j];
  return limit;
}

double valve_adaptation_scale(const ControllerConfig& c) { return c.period / c.valves.force_time_constant; }

void set_command_interface(ControllerConfig& c, CommandInterface interface) {
  if (interface == c.command_interface) return;
  if (c.adaptation_rate_derived) {
    c.adaptation_rate *= interface == CommandInterface::valve ? valve_adaptation_scale(c) : 1 / valve_adaptation_scale(c);
    c.tracking_dead_zone = interface == CommandInterface::valve ? c.valves.hold_window : Vec4::Zero();
  }
  if (c.tracking_error_limit_derived) c.tracking_error_limit = default_tracking_error_limit(interface);
  c.command_interface = interface;
}

}  // namespace exc::control
