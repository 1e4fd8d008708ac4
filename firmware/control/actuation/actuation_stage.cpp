#include "control/actuation/actuation_stage.hpp"

namespace exc::control {

ActuationStage::ActuationStage(const Machine& nominal, const ActuationSettings& settings, CommandInterface interface,
                               double period)
    : valves_interface_(interface == CommandInterface::valve),
      friction_(actuator_friction(nominal)),
      blender_(settings.blend_time),
      lag_(settings.actuator_lag, settings.actuator_lag_target, period, effort_limits_of(nominal)),
      valve_stage_(valve_loop_model(nominal), settings.valves, period) {}

Vec4 ActuationStage::efforts(double t, const Vec4& tau_law, bool restarted) {
  const Vec4 tau = blender_.apply(t, tau_law);
  // last_effort_ stays the effort asked for, the blend's reference.
  if (restarted) lag_.reset(tau);
  last_effort_ = tau;
  return lag_.apply(tau);
}

const ValveCommand& ActuationStage::valve_command(double t, const ControlOutput& out, const Vec4& qd_d, const Vec4& q,
                                                  const ChamberPressures& p, bool holding) {
  valve_stage_.set_holding(holding, out.e);
  if (out.velocity_command) return valve_stage_.from_velocity(out.velocity, q, p.a, p.b);
  const Vec4 tau = blender_.apply(t, out.tau);
  last_effort_ = tau;
  const Vec4 v_ff = qd_d - valve_stage_.settings().position_gain.cwiseProduct(out.e);
  // The cylinders push what the mechanism needs plus what their seals take (the nominal machine's
  // friction, signed by the velocity the valves are asked for, which does not chatter with the
  // sensors' noise; applied() takes it back out of the measured force).
  return valve_stage_.from_force(tau + seal_friction(v_ff, p), v_ff, q, p.a, p.b);
}

AppliedEffort ActuationStage::applied(const ChamberPressures& p, const Vec4& velocity, const Vec4* efforts_sent,
                                      std::uint8_t law_saturated) const {
  AppliedEffort a;
  if (valves_interface_) {
    if (!p.valid) return a;
    // What the cylinders push minus what their seals take (the nominal machine's friction): the
    // effort the mechanism receives, as the model's M_a qdd + h_a + J_t^T F_soil describes it.
    a.effort = valve_stage_.measured_force(p.a, p.b) - seal_friction(velocity, p);
    a.valid = a.measured = true;
    const ValveCommand& v = valve_stage_.last();
    a.suspect = static_cast<std::uint8_t>(v.limited | valve_stage_.off_map(p.a, p.b) | (v.pump_limited ? 0x0F : 0));
    return a;
  }
  if (efforts_sent == nullptr) return a;  // nothing commanded yet, or valves centred
  // The command still holds last cycle's efforts (this cycle's are computed after the law).
  a.effort = lag_.active() ? lag_.delivered() : *efforts_sent;
  a.valid = true;
  a.suspect = static_cast<std::uint8_t>(lag_.clamped() | law_saturated);
  return a;
}

safety::FlowMeasurement ActuationStage::flow_measurement(const Vec4& q, const ChamberPressures& p) const {
  safety::FlowMeasurement m;
  m.position = q;
  // Without pressures (or valves) the compression is unknown: the monitor then sees the motion alone.
  if (!valves_interface_ || !p.valid) return m;
  m.compression = valve_stage_.measured_force(p.a, p.b).cwiseQuotient(valve_stage_.hydraulic_stiffness(q));
  m.at_relief = valve_stage_.at_relief(p.a, p.b);
  return m;
}

void ActuationStage::visit_state(StateVisitor& v) const {
  v.visit("last effort sent", last_effort_);
  v.visit("actuator-lag lead delivered effort", lag_.delivered());
  const ValveCommand& c = valve_stage_.last();
  v.visit("valve stage velocity", c.velocity);
  v.visit("valve stage opening", c.opening);
  v.visit("valve stage spool command", c.spool);
  v.visit("valve stage pilot_a", c.pilot_a);
  v.visit("valve stage pilot_b", c.pilot_b);
  v.visit("valve stage measured force", c.force);
  v.visit("valve stage demanded flow", c.demanded_flow);
  v.visit("valve stage spool lead model", valve_stage_.spool_model());
  v.visit("valve stage force integral", valve_stage_.force_integral());
}

}  // namespace exc::control
