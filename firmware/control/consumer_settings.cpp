// ControllerConfig's members handed to the consumer that reads them, one function per consumer.
#include "control/consumer_settings.hpp"

namespace exc::control {

PidLawSettings pid_law_settings(const ControllerConfig& c) {
  PidLawSettings s;
  s.period = c.period;
  s.gains = c.gains;
  s.lyapunov_q = c.lyapunov_q;
  return s;
}

AdaptiveLawSettings adaptive_law_settings(const ControllerConfig& c) {
  AdaptiveLawSettings s;
  s.period = c.period;
  s.gains = c.gains;
  s.lyapunov_q = c.lyapunov_q;
  s.integral_action = c.integral_action;
  s.lyapunov_q_integral = c.lyapunov_q_integral;
  s.adaptation_rate = c.adaptation_rate;
  s.tracking_dead_zone = c.tracking_dead_zone;
  s.theta_min = c.theta_min;
  s.theta_max = c.theta_max;
  s.theta_initial = c.theta_initial;
  s.regressor_acceleration = c.regressor_acceleration;
  s.external_force = c.external_force;
  s.soil_contact = c.soil_contact;
  s.filter = c.filter;
  return s;
}

SlotineLiSettings slotine_li_settings(const ControllerConfig& c) {
  SlotineLiSettings s;
  s.period = c.period;
  s.lambda = c.sl_lambda;
  s.kd = c.sl_kd;
  s.adaptation_rate = c.sl_adaptation_rate;
  s.theta_min = c.theta_min;
  s.theta_max = c.theta_max;
  s.theta_initial = c.theta_initial;
  return s;
}

FlowLawSettings flow_law_settings(const ControllerConfig& c) {
  FlowLawSettings s;
  s.kp = c.flow_kp;
  return s;
}

ActuationSettings actuation_settings(const ControllerConfig& c) {
  ActuationSettings s;
  s.period = c.period;
  s.command_interface = c.command_interface;
  s.blend_time = c.blend_time;
  s.actuator_lag = c.actuator_lag;
  s.actuator_lag_target = c.actuator_lag_target;
  s.valves = c.valves;
  return s;
}

PathClockSettings path_clock_settings(const ControllerConfig& c) {
  PathClockSettings s;
  s.period = c.period;
  s.stop_ramp_time = c.stop_ramp_time;
  s.pump_pacing = c.pump_pacing;
  s.pump_pacing_share = c.pump_pacing_share;
  return s;
}

}  // namespace exc::control
