// Actuators: ideal, limited and hydraulic (machine.md, "Hydraulics, when a scene needs them").
#include "sim_plant/actuators.hpp"

#include <cmath>

namespace exc::plant {

const char* to_string(ActuatorCommand::Mode m) {
  switch (m) {
    case ActuatorCommand::effort: return "effort";
    case ActuatorCommand::valve: return "valve";
    case ActuatorCommand::pilot: return "pilot";
  }
  return "?";
}

ActuatorModel::ActuatorModel(const Machine& machine, const ActuatorParameters& params, PressureMethod pressures)
    : params_(params) {
  effort_min_ = machine.effort_min();
  effort_max_ = machine.effort_max();
  // Only the hydraulic fidelity validates and uses the circuit; the others keep the cylinder areas
  // (for the sensors' pressure channels) from a circuit with the default hydraulics.
  if (params.fidelity == ActuatorFidelity::hydraulic) {
    circuit_ = HydraulicCircuit(machine, pressures);
  } else {
    Machine areas_only = machine;
    areas_only.hydraulics = HydraulicParameters{};
    circuit_ = HydraulicCircuit(areas_only);
  }
  reset(0.5 * (machine.q_min() + machine.q_max()), Vec4::Zero());
}

void ActuatorModel::reset(const Vec4& q_a, const Vec4& hold) {
  command_ = ActuatorCommand{};
  lagged_ = hold.cwiseMax(effort_min_).cwiseMin(effort_max_);
  if (params_.fidelity == ActuatorFidelity::ideal) command_.value = hold;
  if (params_.fidelity == ActuatorFidelity::limited) command_.value = lagged_;
  circuit_.reset(q_a, lagged_);
  if (params_.fidelity == ActuatorFidelity::hydraulic) command_.mode = ActuatorCommand::valve;
  applied_ = effort(q_a);
}

void ActuatorModel::set_command(const ActuatorCommand& command) {
  command_ = command;
  if (params_.fidelity != ActuatorFidelity::hydraulic) return;
  if (command.mode == ActuatorCommand::pilot) circuit_.command_pilots(command.pilot_a, command.pilot_b);
  else circuit_.command_opening(command.value);
}

Vec4 ActuatorModel::effort(const Vec4& /*q_a*/) const {
  switch (params_.fidelity) {
    case ActuatorFidelity::ideal: return command_.value;
    case ActuatorFidelity::limited: return lagged_;
    case ActuatorFidelity::hydraulic: return circuit_.effort();
  }
  return Vec4::Zero();
}

Vec4 ActuatorModel::effort_over(double dt, const Vec4& q_a) {
  if (params_.fidelity == ActuatorFidelity::limited) {
    // y(t) = c + (y0 - c) exp(-t / lag) toward the clamped command c; its mean over [0, dt] is
    // c + (y0 - c) (lag / dt) (1 - exp(-dt / lag)), and c itself without a lag.
    const Vec4 target = command_.value.cwiseMax(effort_min_).cwiseMin(effort_max_);
    const double w = params_.lag > 0 ? params_.lag / dt * -std::expm1(-dt / params_.lag) : 0.0;
    applied_ = target + w * (lagged_ - target);
  } else {
    applied_ = effort(q_a);
  }
  return applied_;
}

void ActuatorModel::advance(double dt, const Vec4& q_a, const Vec4& qd_a) {
  if (params_.fidelity == ActuatorFidelity::ideal) return;
  if (params_.fidelity == ActuatorFidelity::limited) {
    // First-order lag toward the clamped command, solved exactly over dt (no step-size limit).
    const Vec4 target = command_.value.cwiseMax(effort_min_).cwiseMin(effort_max_);
    const double a = params_.lag > 0 ? -std::expm1(-dt / params_.lag) : 1.0;
    lagged_ += a * (target - lagged_);
    return;
  }
  circuit_.advance(dt, q_a, qd_a);
}

}  // namespace exc::plant
