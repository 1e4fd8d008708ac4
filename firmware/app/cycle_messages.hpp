#pragma once
// The node's per-cycle telemetry messages built from what the cycle computed: EXC_COMMAND (what went
// on the bus and what the valve stage made of the law's effort) and EXC_CONTROLLER (the path, the
// errors, the law's estimates).
#include <cmath>
#include <cstdint>

#include "control/actuation/actuation_stage.hpp"
#include "control/control_types.hpp"
#include "exlcm/command_t.hpp"
#include "exlcm/controller_state_t.hpp"
#include "hal/excavator_interface.hpp"

namespace exc::app {

inline exlcm::command_t command_message(std::int64_t utime, std::int8_t mode, std::int8_t controller, std::int8_t command_interface,
                                        const hal::CommandState& command, const control::ActuationStage& stage,
                                        const control::ControlOutput& out) {
  exlcm::command_t c{};
  c.utime = utime;
  c.mode = mode;
  c.controller = controller;
  c.command_interface = command_interface;
  const bool effort = command.mode == hal::CommandMode::effort;
  const bool valves = command.mode == hal::CommandMode::pilot;
  const control::ValveCommand& v = stage.last_valve_command();
  for (int j = 0; j < 4; ++j) {
    c.effort[j] = effort ? command.value[j] : valves && !out.velocity_command ? stage.last_effort()[j] : 0.0;
    c.valve[j] = effort ? 0.0 : command.value[j];
    c.saturated[j] = ((out.saturated | (valves ? v.limited : 0)) >> j) & 1;
    c.valve_velocity[j] = valves ? v.velocity[j] : 0.0;
    c.pilot_a[j] = valves ? v.pilot_a[j] : 0.0;
    c.pilot_b[j] = valves ? v.pilot_b[j] : 0.0;
    c.force_measured[j] = valves ? v.force[j] : 0.0;
  }
  c.pump_limited = valves && v.pump_limited;
  return c;
}

// theta_true: the plant's true soil parameters (a simulation knows them), null where nobody does.
inline exlcm::controller_state_t controller_message(std::int64_t utime, std::int8_t mode, std::int8_t controller, const Vec4& q_d,
                                                    const Vec4& qd_d, const control::ControlOutput& out, const Vec6* theta_true) {
  exlcm::controller_state_t s{};
  s.utime = utime;
  s.controller = controller;
  s.mode = mode;
  for (int j = 0; j < 4; ++j) {
    s.q_desired[j] = q_d[j];
    s.qd_desired[j] = qd_d[j];
    s.error[j] = out.e[j];
    s.error_rate[j] = out.ed[j];
  }
  for (int i = 0; i < 6; ++i) {
    s.theta_hat[i] = out.theta_hat[i];
    s.theta_true[i] = theta_true != nullptr ? (*theta_true)[i] : std::nan("");
  }
  s.lyapunov = out.lyapunov;
  return s;
}

}  // namespace exc::app
