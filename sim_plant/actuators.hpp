#pragma once
// The machine's actuators at the scene's fidelity (actuator_fidelity.hpp: the registry of fidelities;
// actuator_fidelities.cpp: the shipped ideal, limited and hydraulic). The model holds what every
// fidelity shares: the machine's hydraulic circuit (run by the fidelities that have
// kHydraulicCircuit, else kept for the cylinder areas of the sensors' pressure channels), the effort
// that acted over the last substep, and the fidelity's own dynamics.
#include <memory>

#include "model/hydraulic_geometry.hpp"
#include "model/machine.hpp"
#include "sim_plant/actuator_fidelity.hpp"
#include "sim_plant/hydraulics.hpp"

namespace exc::plant {

class ActuatorModel {
 public:
  // Throws SettingsError when machine.hydraulics is outside its ranges (a fidelity with
  // kHydraulicCircuit), std::invalid_argument for an unregistered fidelity; `pressures` integrates
  // the chambers (chamber.hpp).
  ActuatorModel(const Machine& machine, const ActuatorParameters& params,
                PressureMethod pressures = PressureMethod::backward_euler);
  // The fidelity's dynamics hold a reference to the circuit: not copied, not moved.
  ActuatorModel(const ActuatorModel&) = delete;
  ActuatorModel& operator=(const ActuatorModel&) = delete;

  const ActuatorParameters& parameters() const { return params_; }
  // The fidelity's entry (a copy: the registry may grow after the plant is built).
  const ActuatorFidelityEntry& fidelity() const { return fidelity_; }

  // Start: applied effort = 'hold' (hydraulic: chamber pressures that give it), spools centred.
  void reset(const Vec4& q_a, const Vec4& hold);
  // The command of this cycle (the plant checks the mode against the fidelity first).
  void set_command(const ActuatorCommand& command) { dynamics_->set_command(command); }

  // The effort held on the machine over the next substep of length dt, from the state now: ideal
  // the command; limited the exact mean of its lag's response over the substep (so the command acts
  // within the cycle it is sent in: no delay beyond the lag); hydraulic the chamber pressures now.
  Vec4 effort_over(double dt, const Vec4& q_a) { return applied_ = dynamics_->effort_over(dt, q_a); }
  // The effort at this instant (limited: the lag's state; hydraulic: from the pressures).
  Vec4 effort(const Vec4& q_a) const { return dynamics_->effort(q_a); }
  // The effort effort_over() last returned (the one that acted over the last substep).
  const Vec4& applied() const { return applied_; }
  // Advance the actuator states over dt with the machine's motion (lag, spool, pressures).
  void advance(double dt, const Vec4& q_a, const Vec4& qd_a) { dynamics_->advance(dt, q_a, qd_a); }

  const HydraulicCircuit& hydraulics() const { return circuit_; }
  // Fault injection (kHydraulicCircuit): a spool stuck whatever the command (HydraulicCircuit::stick_spool).
  void stick_spool(int function, double spool) { circuit_.stick_spool(function, spool); }
  void release_spool() { circuit_.release_spool(); }
  void set_pump_flow_scale(double scale) { circuit_.set_pump_flow_scale(scale); }
  void set_pilot_supply(bool on) { circuit_.set_pilot_supply(on); }
  void set_engine_running(bool on) { circuit_.set_engine_running(on); }
  void set_safety_solenoids(bool energised) { circuit_.set_safety_solenoids(energised); }
  void set_swing_lock(bool on) { circuit_.set_swing_lock(on); }
  const Vec4& spool() const { return circuit_.spool(); }
  Vec4 healthy_spool() const { return circuit_.healthy_spool(); }  // HydraulicCircuit::healthy_spool
  const Vec4& pressure_a() const { return circuit_.pressure_a(); }  // cylinder bore side; swing: port A
  const Vec4& pressure_b() const { return circuit_.pressure_b(); }
  // Areas (m^2) of the bore and annulus sides; swing: displacement (m^3/rad) on both.
  const Vec4& area_a() const { return circuit_.area_a(); }
  const Vec4& area_b() const { return circuit_.area_b(); }
  int relief_events() const { return static_cast<int>(circuit_.report().relief_substeps); }

 private:
  ActuatorParameters params_;
  ActuatorFidelityEntry fidelity_;
  Vec4 effort_min_ = Vec4::Zero(), effort_max_ = Vec4::Zero();
  Vec4 applied_ = Vec4::Zero();
  HydraulicCircuit circuit_;
  std::unique_ptr<ActuatorDynamics> dynamics_;
};

}  // namespace exc::plant
