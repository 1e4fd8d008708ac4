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

// The stage's own settings (ControllerConfig's `actuation` member). It takes the command interface
// and the period beside them: those are the bus's and the loop's, which other consumers read too.
struct ActuationSettings {
  double blend_time = 0.2;  // s, bumpless switch fade
  // Actuator lag the firmware compensates (actuator_lag_compensator.hpp): the time constant of the
  // machine's effort response (0: ideal force actuators, the paper's; no compensation) and the one
  // the compensated actuator should show. lag / target is the lead's high-frequency gain.
  double actuator_lag = 0;             // s
  double actuator_lag_target = 0.005;  // s
  ValveLoopSettings valves;  // the valve stage's (valve interface): force loop, spool lead
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, ActuationSettings& s) {
  v("blend_time", s.blend_time);
  v("actuator_lag", s.actuator_lag);
  v("actuator_lag_target", s.actuator_lag_target);
  v("valves", s.valves);
}

class ActuationStage {
 public:
  ActuationStage(const Machine& nominal, const ActuationSettings& settings, CommandInterface interface, double period);

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
