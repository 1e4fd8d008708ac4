// The actuators: the scene's fidelity built from its registry entry over the machine's circuit.
#include "sim_plant/actuators.hpp"

namespace exc::plant {

ActuatorModel::ActuatorModel(const Machine& machine, const ActuatorParameters& params, PressureMethod pressures)
    : params_(params), fidelity_(fidelity_of(params)) {
  effort_min_ = machine.effort_min();
  effort_max_ = machine.effort_max();
  // Only a fidelity that runs the circuit validates and uses the machine's hydraulics; the others
  // keep the cylinder areas (for the sensors' pressure channels) from a circuit with the default ones.
  if (fidelity_.has(kHydraulicCircuit)) {
    circuit_ = HydraulicCircuit(machine, pressures);
  } else {
    Machine areas_only = machine;
    areas_only.hydraulics = HydraulicParameters{};
    circuit_ = HydraulicCircuit(areas_only);
  }
  dynamics_ = fidelity_.make(machine, params, circuit_);
  reset(0.5 * (machine.q_min() + machine.q_max()), Vec4::Zero());
}

void ActuatorModel::reset(const Vec4& q_a, const Vec4& hold) {
  // The chambers at the pressures that hold the effort inside the relief limits, spools centred.
  circuit_.reset(q_a, hold.cwiseMax(effort_min_).cwiseMin(effort_max_));
  dynamics_->reset(q_a, hold);
  applied_ = effort(q_a);
}

}  // namespace exc::plant
