#pragma once
// The actuators at three fidelities (machine.md, "Hydraulics"; hydraulics.md):
//   ideal      the commanded swing torque and cylinder forces act as given (the paper);
//   limited    efforts clamped to the relief limits, a first-order lag, speed limits and end stops
//              (the last two are applied by the plant to the state after each substep);
//   hydraulic  the machine's hydraulics (hydraulics.hpp): pumps with flow sharing, pilot-operated
//              spools with lag and dead zones, chamber pressures, reliefs, make-up valves, the swing
//              motor; commanded by spool opening or pilot pressures; the effort is p_A A_A - p_B A_B.
#include "model/machine.hpp"
#include "sim_plant/hydraulics.hpp"
#include "sim_plant/orifice.hpp"

namespace exc::plant {

enum class ActuatorFidelity { ideal, limited, hydraulic };
const char* to_string(ActuatorFidelity f);

struct ActuatorParameters {
  ActuatorFidelity fidelity = ActuatorFidelity::ideal;
  double lag = 0.02;                  // s, limited: effort time constant (0: none)
  double valve_time_constant = 0.03;  // s, hydraulic: spool lag (pilot-operated mobile valve, 30-100 ms)
  double bulk_modulus = 1.0e9;        // Pa, effective (oil with hoses)
  double dead_volume = 0.002;         // m^3, oil in each cylinder chamber's lines at full retraction
  double swing_volume = 0.01;         // m^3, oil on each side of the swing motor
  double supply_pressure = 0;         // Pa, the pumps' pressure limit; 0: hydraulic.main_relief_pressure
  double tank_pressure = 0.3e6;       // Pa, return-line back pressure (the make-up valves draw from it)
  double valve_pressure_drop = 5e6;   // Pa: a fully open meter-out passes the speed-limit flow at this drop
  double laminar_pressure = 0.2e6;    // Pa: below this drop the orifice flow is linear in dp
  HydraulicParameters hydraulic;      // the rest of the hydraulic machine (C++ only for now)
};

// What the controller sends each cycle:
//   effort  swing torque (N m) and cylinder forces (N) in 'value', positive pushes longer;
//   valve   signed spool openings -1..1 in 'value' (positive extends / swings counter-clockwise);
//   pilot   pilot pressures 0..hydraulic.pilot_full_stroke (Pa) on each spool's A end (opens
//           P->A: extends / swings counter-clockwise) and B end, as a real valve block takes them.
struct ActuatorCommand {
  enum Mode { effort, valve, pilot } mode = effort;
  Vec4 value = Vec4::Zero();
  Vec4 pilot_a = Vec4::Zero(), pilot_b = Vec4::Zero();
};
const char* to_string(ActuatorCommand::Mode m);

class ActuatorModel {
 public:
  ActuatorModel() = default;
  // Throws std::invalid_argument when a hydraulic parameter is outside its range (hydraulic fidelity).
  ActuatorModel(const Machine& machine, const ActuatorParameters& params);

  const ActuatorParameters& parameters() const { return params_; }

  // Start: applied effort = 'hold' (hydraulic: chamber pressures that give it), spools centred.
  void reset(const Vec4& q_a, const Vec4& hold);
  // The command of this cycle (the plant checks the mode against the fidelity first).
  void set_command(const ActuatorCommand& command);

  // The effort held on the machine over the next substep of length dt, from the state now: ideal
  // the command; limited the exact mean of its lag's response over the substep (so the command acts
  // within the cycle it is sent in: no delay beyond the lag); hydraulic the chamber pressures now.
  Vec4 effort_over(double dt, const Vec4& q_a);
  // The effort at this instant (limited: the lag's state; hydraulic: from the pressures).
  Vec4 effort(const Vec4& q_a) const;
  // The effort effort_over() last returned (the one that acted over the last substep).
  const Vec4& applied() const { return applied_; }
  // Advance the actuator states over dt with the machine's motion (lag, spool, pressures).
  void advance(double dt, const Vec4& q_a, const Vec4& qd_a);

  const HydraulicCircuit& hydraulics() const { return circuit_; }
  const Vec4& spool() const { return circuit_.spool(); }
  const Vec4& pressure_a() const { return circuit_.pressure_a(); }  // cylinder bore side; swing: port A
  const Vec4& pressure_b() const { return circuit_.pressure_b(); }
  // Areas (m^2) of the bore and annulus sides; swing: displacement (m^3/rad) on both.
  const Vec4& area_a() const { return circuit_.area_a(); }
  const Vec4& area_b() const { return circuit_.area_b(); }
  int relief_events() const { return static_cast<int>(circuit_.report().relief_substeps); }

 private:
  ActuatorParameters params_;
  Vec4 effort_min_ = Vec4::Zero(), effort_max_ = Vec4::Zero();
  ActuatorCommand command_;
  Vec4 lagged_ = Vec4::Zero();  // limited: the lag's state
  Vec4 applied_ = Vec4::Zero();
  HydraulicCircuit circuit_;
};

}  // namespace exc::plant
