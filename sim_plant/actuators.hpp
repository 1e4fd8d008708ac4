#pragma once
// The actuators at three fidelities (machine.md, "Hydraulics"):
//   ideal      the commanded swing torque and cylinder forces act as given (the paper);
//   limited    efforts clamped to the relief limits, a first-order lag, speed limits and end stops
//              (the last two are applied by the plant to the state after each substep);
//   hydraulic  commanded by valve opening: spool lag, orifice flow, chamber pressures with bulk
//              modulus, relief valve; the effort is the pressure difference times the area.
#include "model/machine.hpp"

namespace exc::plant {

enum class ActuatorFidelity { ideal, limited, hydraulic };
const char* to_string(ActuatorFidelity f);

struct ActuatorParameters {
  ActuatorFidelity fidelity = ActuatorFidelity::ideal;
  double lag = 0.02;                  // s, limited: effort time constant (0: none)
  double valve_time_constant = 0.03;  // s, hydraulic: spool lag (pilot-operated mobile valve)
  double bulk_modulus = 1.0e9;        // Pa, effective (oil with hoses)
  double dead_volume = 0.002;         // m^3, oil in each cylinder chamber's lines at full retraction
  double swing_volume = 0.01;         // m^3, oil on each side of the swing motor
  double supply_pressure = 0;         // Pa, 0: the relief pressure (constant-pressure supply)
  double tank_pressure = 0.3e6;       // Pa
  double valve_pressure_drop = 5e6;   // Pa: a fully open valve passes the speed-limit flow at this drop
  double laminar_pressure = 0.2e6;    // Pa: below this drop the orifice flow is linear in dp
};

// What the controller sends each cycle. effort: swing torque (N m) and cylinder forces (N), positive
// pushes longer; valve: openings -1..1 (positive extends / swings counter-clockwise).
struct ActuatorCommand {
  enum Mode { effort, valve } mode = effort;
  Vec4 value = Vec4::Zero();
};

class ActuatorModel {
 public:
  ActuatorModel() = default;
  ActuatorModel(const Machine& machine, const ActuatorParameters& params);

  const ActuatorParameters& parameters() const { return params_; }

  // Start: applied effort = 'hold' (hydraulic: chamber pressures that give it), spools closed.
  void reset(const Vec4& q_a, const Vec4& hold);
  // The command of this cycle (the plant checks the mode against the fidelity first).
  void set_command(const ActuatorCommand& command) { command_ = command; }

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

  const Vec4& spool() const { return spool_; }
  const Vec4& pressure_a() const { return p_a_; }  // cylinder bore side; swing: port A
  const Vec4& pressure_b() const { return p_b_; }
  // Areas (m^2) of the bore and annulus sides; swing: displacement (m^3/rad) on both.
  const Vec4& area_a() const { return area_a_; }
  const Vec4& area_b() const { return area_b_; }
  int relief_events() const { return relief_events_; }

 private:
  double chamber_volume_a(int i, const Vec4& q_a) const;
  double chamber_volume_b(int i, const Vec4& q_a) const;

  ActuatorParameters params_;
  Vec4 effort_min_ = Vec4::Zero(), effort_max_ = Vec4::Zero(), q_min_ = Vec4::Zero(), q_max_ = Vec4::Zero();
  Vec4 speed_max_ = Vec4::Zero();
  double relief_ = 0, supply_ = 0;
  Vec4 area_a_ = Vec4::Zero(), area_b_ = Vec4::Zero(), valve_gain_ = Vec4::Zero();
  ActuatorCommand command_;
  Vec4 lagged_ = Vec4::Zero();  // limited: the lagged effort
  Vec4 applied_ = Vec4::Zero();
  Vec4 spool_ = Vec4::Zero(), p_a_ = Vec4::Zero(), p_b_ = Vec4::Zero();
  int relief_events_ = 0;
};

// Orifice flow (machine.md): Q = K_v x_v sqrt(dp), linear below the laminar pressure so that the
// flow and its derivative stay finite at dp = 0. Returns the flow for unit gain and opening, and
// its derivative with respect to dp.
void orifice_flow(double dp, double laminar_pressure, double& flow, double& dflow_ddp);

}  // namespace exc::plant
