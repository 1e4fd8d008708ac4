// The defaults a nominal machine, the command interface and the other settings imply, in one place
// (the reader derives them as it reads; a bench switches a configuration's interface with them).
// Nothing here reads a file.
#include "control/controller_config.hpp"

#include <algorithm>

namespace exc::control {

Vec4 default_tracking_error_limit(CommandInterface interface) {
  if (interface != CommandInterface::valve) return safety::SupervisorSettings{}.tracking_error_limit;
  Vec4 limit;
  for (int j = 0; j < 4; ++j) limit[j] = kTrackingLimitMultiple * kValveMachineReach[j];
  return limit;
}

double valve_adaptation_scale(const ControllerConfig& c) { return c.period / c.actuation.valves.force_time_constant; }

void derive_defaults(ControllerConfig& c, const Machine& nominal) {
  const GivenSettings& given = c.given;
  const bool valves = c.command_interface == CommandInterface::valve;
  // The force loop is as fast as the spools it closes through (at least 5 ms); the spool lead aims
  // at a third of their lag.
  if (!given.force_time_constant) c.actuation.valves.force_time_constant = std::max(nominal.hydraulics.valve_time_constant, 0.005);
  if (!given.spool_lag_target) c.actuation.valves.spool_lag_target = nominal.hydraulics.valve_time_constant / 3;
  // A fifth of the force loop's bandwidth, so the position correction the flow feedforward carries
  // stays clear of the loop that delivers it.
  if (!given.position_gain) c.actuation.valves.position_gain = Vec4::Constant(1 / (5 * c.actuation.valves.force_time_constant));
  // Shares of each function's top speed (kPlausibilityVelocityShare, kFrozenSpeedShare).
  if (!given.velocity_floor) c.supervisor.plausibility.velocity_floor = kPlausibilityVelocityShare * nominal.speed_max();
  if (!given.frozen_speed) c.supervisor.plausibility.frozen_speed = kFrozenSpeedShare * nominal.speed_max();
  // Eq. 27 reads the tracking error as the soil's doing. Through the valves the effort arrives
  // through the force loop's T_f, whose lag the update would read as soil: the rates are the
  // force-commanded machine's scaled by period / T_f, and an error inside the valve stage's hold
  // window (which the valves cannot resolve) is left out of the update.
  if (!given.adaptation_rate)
    c.adaptation.rate = AdaptationSettings{}.rate * (valves ? valve_adaptation_scale(c) : 1.0);
  if (!given.tracking_dead_zone) c.adaptation.tracking_dead_zone = valves ? c.actuation.valves.hold_window : Vec4::Zero();
  // The observer's residual carries the filtered acceleration: it stays well inside that filter's band.
  if (!given.observer_cutoff) c.adaptation.external_force.cutoff_hz = c.filter.acceleration_cutoff_hz / 3;
  if (!given.tracking_error_limit) c.supervisor.tracking_error_limit = default_tracking_error_limit(c.command_interface);
  c.filter.period = c.period;
}

ControllerConfig controller_defaults(const Machine& nominal) {
  ControllerConfig c;
  derive_defaults(c, nominal);
  return c;
}

void set_command_interface(ControllerConfig& c, CommandInterface interface, const Machine& nominal) {
  c.command_interface = interface;
  derive_defaults(c, nominal);
}

}  // namespace exc::control
