// Actuators: ideal, limited and hydraulic (machine.md, "Hydraulics, when a scene needs them").
#include "sim_plant/actuators.hpp"

#include <algorithm>
#include <cmath>

namespace exc::plant {

const char* to_string(ActuatorFidelity f) {
  switch (f) {
    case ActuatorFidelity::ideal: return "ideal";
    case ActuatorFidelity::limited: return "limited";
    case ActuatorFidelity::hydraulic: return "hydraulic";
  }
  return "?";
}

void orifice_flow(double dp, double laminar_pressure, double& flow, double& dflow_ddp) {
  const double a = std::abs(dp);
  if (a < laminar_pressure) {
    // Linear branch meeting sqrt at dp = laminar_pressure (same value there).
    const double s = 1.0 / std::sqrt(laminar_pressure);
    flow = dp * s;
    dflow_ddp = s;
  } else {
    const double r = std::sqrt(a);
    flow = dp > 0 ? r : -r;
    dflow_ddp = 0.5 / r;
  }
}

ActuatorModel::ActuatorModel(const Machine& machine, const ActuatorParameters& params)
    : params_(params) {
  effort_min_ = machine.effort_min();
  effort_max_ = machine.effort_max();
  q_min_ = machine.q_min();
  q_max_ = machine.q_max();
  speed_max_ = machine.speed_max();
  relief_ = machine.relief_pressure;
  supply_ = params.supply_pressure > 0 ? params.supply_pressure : relief_;
  // Push force = bore area x relief, pull = annulus area x relief (machine.md); the swing motor's
  // displacement gives the torque limit at the relief pressure.
  for (int i = 0; i < kNumActive; ++i) {
    area_a_[i] = effort_max_[i] / relief_;
    area_b_[i] = -effort_min_[i] / relief_;
    // Fully open at the nominal drop: the flow of the speed limit on the bore side.
    valve_gain_[i] = area_a_[i] * speed_max_[i] / std::sqrt(params.valve_pressure_drop);
  }
  reset(0.5 * (q_min_ + q_max_), Vec4::Zero());
}

double ActuatorModel::chamber_volume_a(int i, const Vec4& q_a) const {
  if (i == 0) return params_.swing_volume;
  const double stroke = std::clamp(q_a[i] - q_min_[i], 0.0, q_max_[i] - q_min_[i]);
  return params_.dead_volume + area_a_[i] * stroke;
}

double ActuatorModel::chamber_volume_b(int i, const Vec4& q_a) const {
  if (i == 0) return params_.swing_volume;
  const double stroke = std::clamp(q_max_[i] - q_a[i], 0.0, q_max_[i] - q_min_[i]);
  return params_.dead_volume + area_b_[i] * stroke;
}

void ActuatorModel::reset(const Vec4& q_a, const Vec4& hold) {
  command_ = ActuatorCommand{};
  lagged_ = hold.cwiseMax(effort_min_).cwiseMin(effort_max_);
  if (params_.fidelity == ActuatorFidelity::ideal) command_.value = hold;
  if (params_.fidelity == ActuatorFidelity::limited) command_.value = lagged_;
  spool_.setZero();
  relief_events_ = 0;
  // Chamber pressures that hold the effort, the lower side at twice the tank pressure.
  const double low = 2.0 * params_.tank_pressure;
  for (int i = 0; i < kNumActive; ++i) {
    const double f = lagged_[i];
    if (f >= 0) {
      p_b_[i] = low;
      p_a_[i] = std::clamp((f + area_b_[i] * low) / area_a_[i], params_.tank_pressure, relief_);
    } else {
      p_a_[i] = low;
      p_b_[i] = std::clamp((area_a_[i] * low - f) / area_b_[i], params_.tank_pressure, relief_);
    }
  }
  if (params_.fidelity == ActuatorFidelity::hydraulic) command_.mode = ActuatorCommand::valve;
  applied_ = effort(q_a);
}

Vec4 ActuatorModel::effort(const Vec4& /*q_a*/) const {
  switch (params_.fidelity) {
    case ActuatorFidelity::ideal: return command_.value;
    case ActuatorFidelity::limited: return lagged_;
    case ActuatorFidelity::hydraulic: return area_a_.cwiseProduct(p_a_) - area_b_.cwiseProduct(p_b_);
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
  // Hydraulic. Spool: first-order lag toward the opening, exact over dt.
  const Vec4 opening = command_.value.cwiseMax(Vec4::Constant(-1.0)).cwiseMin(Vec4::Constant(1.0));
  const double a = params_.valve_time_constant > 0 ? 1.0 - std::exp(-dt / params_.valve_time_constant) : 1.0;
  spool_ += a * (opening - spool_);
  const double pt = params_.tank_pressure, ps = supply_, lam = params_.laminar_pressure;
  for (int i = 0; i < kNumActive; ++i) {
    const double x = spool_[i];
    const double kv_a = valve_gain_[i];
    const double kv_b = valve_gain_[i] * area_b_[i] / area_a_[i];
    double g, dg;
    // Chamber A: from supply when x > 0, to tank when x < 0.
    double qa, dqa;
    if (x >= 0) { orifice_flow(ps - p_a_[i], lam, g, dg); qa = kv_a * x * g; dqa = -kv_a * x * dg; }
    else { orifice_flow(p_a_[i] - pt, lam, g, dg); qa = kv_a * x * g; dqa = kv_a * x * dg; }
    // Chamber B: to tank when x > 0, from supply when x < 0.
    double qb, dqb;
    if (x >= 0) { orifice_flow(p_b_[i] - pt, lam, g, dg); qb = -kv_b * x * g; dqb = -kv_b * x * dg; }
    else { orifice_flow(ps - p_b_[i], lam, g, dg); qb = -kv_b * x * g; dqb = kv_b * x * dg; }
    // dp/dt = beta / V (Q - A ydot) (machine.md); linearly implicit in the chamber's own pressure,
    // because the orifice makes it stiff (beta K_v / V reaches 1e4 1/s near the end of stroke).
    const double ca = params_.bulk_modulus / chamber_volume_a(i, q_a);
    const double cb = params_.bulk_modulus / chamber_volume_b(i, q_a);
    const double fa = ca * (qa - area_a_[i] * qd_a[i]);
    const double fb = cb * (qb + area_b_[i] * qd_a[i]);
    double pa = p_a_[i] + dt * fa / (1.0 - dt * ca * dqa);
    double pb = p_b_[i] + dt * fb / (1.0 - dt * cb * dqb);
    // Relief valve (ideal, crack = full flow) and cavitation floor at tank pressure.
    if (pa > relief_ || pb > relief_) ++relief_events_;
    p_a_[i] = std::clamp(pa, pt, relief_);
    p_b_[i] = std::clamp(pb, pt, relief_);
  }
}

}  // namespace exc::plant
