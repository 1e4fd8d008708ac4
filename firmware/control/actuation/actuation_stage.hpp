#pragma once
// The stages after the control law: what the law asks for made a command the machine takes, and
// what the machine applied read back for the law. On the effort interface (force actuators) the
// bumpless blend and the actuator-lag lead give the efforts to send; on the valve interface the
// valve stage (valve_inner_loop.hpp) gives the spools' pilot pressures, its force loop closing on the
// measured chamber pressures with the nominal machine's seal friction added. Allocation-free after
// construction.
#include <cstdint>

#include "control/actuation/actuator_lag_compensator.hpp"
#include "control/actuation/command_blender.hpp"
#include "control/actuation/command_interface.hpp"
#include "control/actuation/valve_inner_loop.hpp"
#include "control/control_types.hpp"
#include "model/actuator_friction.hpp"
#include "safety/supervisor.hpp"

namespace exc::control {

// The chamber pressures of a sensor set (Pa), valid only when the machine measures them.
struct ChamberPressures {
  bool valid = false;
  Vec4 a = Vec4::Zero(), b = Vec4::Zero();
};

// What the stage reads, its own: ControllerConfig's members of the same names, which hold their
// meaning and defaults (controller_config.hpp; consumer_settings.hpp hands them over).
struct ActuationSettings {
  double period = 1e-3;  // s
  CommandInterface command_interface = CommandInterface::effort;
  double blend_time = 0;           // s, bumpless switch fade
  double actuator_lag = 0;         // s, the effort lag the lead compensates (0: none)
  double actuator_lag_target = 0;  // s, the lag the compensated actuator should show
  ValveLoopSettings valves;        // the valve stage's (valve interface)
};

class ActuationStage {
 public:
  ActuationStage(const Machine& nominal, const ActuationSettings& settings);

  bool valves() const { return valves_interface_; }
  // Entering hold or track after a stop or at start-up: the valve stage forgets its filters.
  void restart() { valve_stage_.reset(); }
  // A switch between the effort-commanding modes starts from the last command and fades to the law's.
  void switch_modes(double t, const Vec4& first_new) { blender_.on_switch(t, last_effort_, first_new); }
  // The safe state's centred valves: no effort asked.
  void centre() { last_effort_.setZero(); }

  // Effort interface: this cycle's efforts for the law's tau (restarted: the actuator is taken to
  // deliver what the law asks for first, as the plant's actuators hold their effort).
  Vec4 efforts(double t, const Vec4& tau, bool restarted);
  // Valve interface: this cycle's valve command for the law's output (a flow law's velocity, or an
  // effort through the force loop); holding: the machine is told to hold its pose.
  const ValveCommand& valve_command(double t, const ControlOutput& out, const Vec4& qd_d, const Vec4& q, const ChamberPressures& p,
                                    bool holding);

  // The efforts the machine applied over the last cycle as far as the firmware knows them: measured
  // (valve interface, from the pressures, less the seals' friction at the estimated velocity) or the
  // delivered-effort model of the last command (efforts_sent: the efforts the bus carried, none when
  // nothing was commanded yet or the valves were centred).
  AppliedEffort applied(const ChamberPressures& p, const Vec4& velocity, const Vec4* efforts_sent, std::uint8_t law_saturated) const;
  // What the stage did not deliver last cycle (a clamped lead, a fully open valve, a valve centred in
  // position while the machine holds), bit j: the laws' integrators and updates hold there. Without
  // the last, a PID integral winds up against the closed valve and the cylinder's dry friction while
  // the load sits inside the hold window and throws the load past the pose when the valve reopens
  // (stick-slip hunting: docs/control.md, "Holding still").
  std::uint8_t limited() const {
    return valves_interface_ ? static_cast<std::uint8_t>(valve_stage_.last().limited | valve_stage_.in_position())
                             : lag_.clamped();
  }
  // What the flow plausibility monitor measures: positions, the oil columns' compression F / K_h
  // (none without pressures or valves) and the functions at a relief.
  safety::FlowMeasurement flow_measurement(const Vec4& q, const ChamberPressures& p) const;

  const Vec4& last_effort() const { return last_effort_; }  // the blended effort asked for (telemetry)
  const ValveCommand& last_valve_command() const { return valve_stage_.last(); }
  const ValveInnerLoop& valve_stage() const { return valve_stage_; }
  const ActuatorLagCompensator& lag_lead() const { return lag_; }
  void visit_state(StateVisitor& v) const;

 private:
  // The nominal machine's seal friction at velocity v and these chamber pressures (actuator_friction.hpp).
  Vec4 seal_friction(const Vec4& v, const ChamberPressures& p) const { return smooth_friction(friction_, v, p.a, p.b); }

  bool valves_interface_;
  ActuatorFriction friction_;  // the nominal machine's
  CommandBlender blender_;
  ActuatorLagCompensator lag_;
  ValveInnerLoop valve_stage_;
  Vec4 last_effort_ = Vec4::Zero();
};

}  // namespace exc::control
