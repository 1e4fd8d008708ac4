// The shipped actuator fidelities (machine.md, "Hydraulics"; hydraulics.md), one line each in
// shipped_fidelities, and the registry that holds them:
//   ideal      the commanded swing torque and cylinder forces act as given (the paper);
//   limited    efforts clamped to the relief limits, a first-order lag, speed limits and end stops
//              (the last two are applied by the plant to the state after each substep);
//   hydraulic  the machine's hydraulics (hydraulics.hpp): pumps with flow sharing, pilot-operated
//              spools with lag and dead zones, chamber pressures, reliefs, make-up valves, the swing
//              motor; commanded by spool opening or pilot pressures; the effort is p_A A_A - p_B A_B.
#include "sim_plant/actuator_fidelity.hpp"

#include <cmath>
#include <stdexcept>

namespace exc::plant {
namespace {

// The commanded efforts act as given, from the cycle they are sent in.
class IdealActuators final : public ActuatorDynamics {
 public:
  IdealActuators(const Machine&, const ActuatorParameters&, HydraulicCircuit&) {}
  void reset(const Vec4&, const Vec4& hold) override { command_ = hold; }
  void set_command(const ActuatorCommand& command) override { command_ = command.value; }
  Vec4 effort(const Vec4&) const override { return command_; }

 private:
  Vec4 command_ = Vec4::Zero();
};

// A first-order lag toward the command clamped to the relief limits, solved exactly over each substep
// (no step-size limit). The speed limits and end stops are the plant's (kSpeedLimits, kEndStops).
class LimitedActuators final : public ActuatorDynamics {
 public:
  LimitedActuators(const Machine& machine, const ActuatorParameters& params, HydraulicCircuit&)
      : lag_(params.lag), effort_min_(machine.effort_min()), effort_max_(machine.effort_max()) {}
  void reset(const Vec4&, const Vec4& hold) override { command_ = lagged_ = clamped(hold); }
  void set_command(const ActuatorCommand& command) override { command_ = command.value; }
  Vec4 effort(const Vec4&) const override { return lagged_; }
  // y(t) = c + (y0 - c) exp(-t / lag) toward the clamped command c: its exact mean over the substep,
  // c + (y0 - c) (lag / dt) (1 - exp(-dt / lag)), so the command acts within the cycle it is sent in
  // (no delay beyond the lag); c itself without a lag.
  Vec4 effort_over(double dt, const Vec4&) override {
    const Vec4 target = clamped(command_);
    const double w = lag_ > 0 ? lag_ / dt * -std::expm1(-dt / lag_) : 0.0;
    return target + w * (lagged_ - target);
  }
  void advance(double dt, const Vec4&, const Vec4&) override {
    const double a = lag_ > 0 ? -std::expm1(-dt / lag_) : 1.0;
    lagged_ += a * (clamped(command_) - lagged_);
  }

 private:
  Vec4 clamped(const Vec4& e) const { return e.cwiseMax(effort_min_).cwiseMin(effort_max_); }
  double lag_;
  Vec4 effort_min_, effort_max_;
  Vec4 command_ = Vec4::Zero(), lagged_ = Vec4::Zero();
};

// The machine's circuit: the effort is p_A A_A - p_B A_B of its chamber pressures.
class HydraulicActuators final : public ActuatorDynamics {
 public:
  HydraulicActuators(const Machine&, const ActuatorParameters&, HydraulicCircuit& circuit) : circuit_(&circuit) {}
  void reset(const Vec4&, const Vec4&) override {}  // the circuit starts at the holding pressures (ActuatorModel)
  void set_command(const ActuatorCommand& command) override {
    if (command.mode == ActuatorCommand::pilot) circuit_->command_pilots(command.pilot_a, command.pilot_b);
    else circuit_->command_opening(command.value);
  }
  Vec4 effort(const Vec4&) const override { return circuit_->effort(); }
  void advance(double dt, const Vec4& q_a, const Vec4& qd_a) override { circuit_->advance(dt, q_a, qd_a); }

 private:
  HydraulicCircuit* circuit_;
};

double limited_lag(const ActuatorParameters& p) { return p.lag; }

ActuatorFidelityRegistry shipped_fidelities() {
  ActuatorFidelityRegistry r;
  r.add({"ideal", "the commanded efforts act as given (the paper)", build_actuators<IdealActuators>});
  r.add({"limited", "efforts clamped to the relief limits, a first-order lag, speed limits, end stops",
         build_actuators<LimitedActuators>, ActuatorInput::efforts, kEndStops | kSpeedLimits, limited_lag});
  r.add({"hydraulic", "the machine's hydraulics (pumps, spools, chambers, reliefs), valve commands",
         build_actuators<HydraulicActuators>, ActuatorInput::valves, kHydraulicCircuit | kEndStops});
  return r;
}

}  // namespace

const char* to_string(ActuatorCommand::Mode m) {
  switch (m) {
    case ActuatorCommand::effort: return "effort";
    case ActuatorCommand::valve: return "valve";
    case ActuatorCommand::pilot: return "pilot";
  }
  return "?";
}

void ActuatorFidelityRegistry::add(ActuatorFidelityEntry entry) {
  if (!entry.make) throw std::invalid_argument("actuator fidelity '" + entry.name + "' has no factory");
  NameRegistry::add(std::move(entry));
}

ActuatorFidelityRegistry& actuator_fidelities() {
  static ActuatorFidelityRegistry registry = shipped_fidelities();
  return registry;
}

void register_actuator_fidelity(ActuatorFidelityEntry entry) { actuator_fidelities().add(std::move(entry)); }

}  // namespace exc::plant
