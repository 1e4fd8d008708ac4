#pragma once
// The actuators at three fidelities (machine.md, "Hydraulics"; hydraulics.md):
//   ideal      the commanded swing torque and cylinder forces act as given (the paper);
//   limited    efforts clamped to the relief limits, a first-order lag, speed limits and end stops
//              (the last two are applied by the plant to the state after each substep);
//   hydraulic  the machine's hydraulics (hydraulics.hpp): pumps with flow sharing, pilot-operated
//              spools with lag and dead zones, chamber pressures, reliefs, make-up valves, the swing
//              motor; commanded by spool opening or pilot pressures; the effort is p_A A_A - p_B A_B.
#include "model/machine.hpp"
#include "settings/enum_table.hpp"
#include "sim_plant/hydraulics.hpp"
#include "model/hydraulic_geometry.hpp"

namespace exc::plant {

enum class ActuatorFidelity { ideal, limited, hydraulic };
// The names a scene's actuators.fidelity takes.
inline constexpr settings::EnumTable<ActuatorFidelity, 3> kActuatorFidelities{{{
    {ActuatorFidelity::ideal, "ideal", "the commanded efforts act as given (the paper)"},
    {ActuatorFidelity::limited, "limited", "efforts clamped to the relief limits, a first-order lag, speed limits, end stops"},
    {ActuatorFidelity::hydraulic, "hydraulic", "the machine's hydraulics (pumps, spools, chambers, reliefs), valve commands"},
}}};
inline const char* to_string(ActuatorFidelity f) { return kActuatorFidelities.name_of(f); }

// The scene's `actuators:` section. The hydraulic machine's numbers are the machine file's
// (Machine::hydraulics): a scene chooses how the actuators are modelled, the machine what they are.
struct ActuatorParameters {
  ActuatorFidelity fidelity = ActuatorFidelity::ideal;
  double lag = 0.02;                  // s, limited: effort time constant (0: none)
};

// What the controller sends each cycle:
//   effort  swing torque (N m) and cylinder forces (N) in 'value', positive pushes longer;
//   valve   signed spool openings -1..1 in 'value' (positive extends / swings counter-clockwise);
//   pilot   pilot pressures 0..hydraulics.pilot_full_stroke (Pa) on each spool's A end (opens
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
  // Throws SettingsError when machine.hydraulics is outside its ranges (hydraulic fidelity);
  // `pressures` integrates the chambers (chamber.hpp).
  ActuatorModel(const Machine& machine, const ActuatorParameters& params,
                PressureMethod pressures = PressureMethod::backward_euler);

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
  // Fault injection (hydraulic): a spool stuck whatever the command (HydraulicCircuit::stick_spool).
  void stick_spool(int function, double spool) { circuit_.stick_spool(function, spool); }
  void release_spool() { circuit_.release_spool(); }
  void set_pump_flow_scale(double scale) { circuit_.set_pump_flow_scale(scale); }
  void set_pilot_supply(bool on) { circuit_.set_pilot_supply(on); }
  void set_engine_running(bool on) { circuit_.set_engine_running(on); }
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
