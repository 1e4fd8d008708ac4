#include "control/actuation/valve_inner_loop.hpp"

#include <algorithm>
#include <cmath>

namespace exc::control {
namespace {

// The orifice law per unit gain for a drop across it (none when the drop is not positive).
double orifice(double dp, double laminar) { return dp > 0 ? orifice_unit_flow(dp, laminar) : 0.0; }

EffortLimits spool_limits() {
  EffortLimits l;
  l.min = Vec4::Constant(-1);
  l.max = Vec4::Constant(1);
  return l;
}

}  // namespace

ValveLoopModel valve_loop_model(const Machine& nominal) {
  ValveLoopModel m;
  m.geometry = hydraulic_geometry(nominal);
  m.hydraulics = nominal.hydraulics;
  m.q_min = nominal.q_min();
  m.q_max = nominal.q_max();
  return m;
}

ValveInnerLoop::ValveInnerLoop(const ValveLoopModel& model, const ValveLoopSettings& settings, double period)
    : model_(model),
      settings_(settings),
      spool_lead_(settings.spool_lag_target > 0 ? model.hydraulics.valve_time_constant : 0.0,
                  settings.spool_lag_target > 0 ? settings.spool_lag_target : 1.0, period, spool_limits()),
      hold_alpha_(settings.hold_filter_time > 0 ? 1.0 - std::exp(-period / settings.hold_filter_time) : 1.0),
      period_(period),
      hold_speed_(settings.hold_filter_time > 0 ? Vec4(settings.hold_window / settings.hold_filter_time) : Vec4::Zero()),
      level_alpha_(1.0 - std::exp(-period / (5 * settings.force_time_constant))) {}

void ValveInnerLoop::reset() {
  spool_lead_.reset(Vec4::Zero());
  in_position_ = 0;
  settled_ = 0;
  holding_ = false;
  correction_time_.setZero();
  correction_start_.setZero();
  raw_error_.setZero();
  hold_error_.setZero();
  force_integral_.setZero();
  level_primed_ = false;
  command_ = ValveCommand{};
}

void ValveInnerLoop::set_holding(bool holding, const Vec4& error) {
  holding_ = holding;
  raw_error_ = error;
  if (!holding) {
    in_position_ = 0;
    settled_ = 0;
    hold_error_ = error;
    return;
  }
  hold_error_ += hold_alpha_ * (error - hold_error_);
  std::uint8_t inside = 0;
  bool reentered = false;
  for (int i = 0; i < kNumActive; ++i) {
    const std::uint8_t bit = static_cast<std::uint8_t>(1u << i);
    const double e = std::abs(hold_error_[i]);
    if (e < settings_.hold_window[i]) inside |= bit;
    else if (e > kHoldReentry * settings_.hold_window[i] && (in_position_ & bit)) reentered = true;
  }
  // A function is corrected again past kHoldReentry windows; and then so is every other function
  // outside its window (in the band up to kHoldReentry): a correction's reaction throws its
  // neighbours (the links couple them), and one held on its closed valve with its error already in
  // the band was thrown past the tolerance before its own correction began. Each is centred again
  // once inside its own window.
  if (reentered) in_position_ &= inside;
  for (int i = 0; i < kNumActive; ++i) {
    const std::uint8_t bit = static_cast<std::uint8_t>(1u << i);
    if (inside & bit) in_position_ |= bit;
    else if (std::abs(hold_error_[i]) > kHoldReentry * settings_.hold_window[i]) in_position_ &= static_cast<std::uint8_t>(~bit);
  }
  settled_ |= in_position_;
}

Vec4 ValveInnerLoop::measured_force(const Vec4& p_a, const Vec4& p_b) const {
  return model_.geometry.area_a.cwiseProduct(p_a) - model_.geometry.area_b.cwiseProduct(p_b);
}

std::uint8_t ValveInnerLoop::at_relief(const Vec4& p_a, const Vec4& p_b) const {
  const HydraulicParameters& h = model_.hydraulics;
  std::uint8_t bits = 0;
  for (int i = 0; i < kNumActive; ++i) {
    const double relief = i == 0 ? h.swing_relief_pressure : h.port_relief_pressure;
    const double high = std::min(model_.main_relief() - h.load_sensing_margin, relief);
    if (std::max(p_a[i], p_b[i]) > high) bits |= static_cast<std::uint8_t>(1u << i);
  }
  return bits;
}

std::uint8_t ValveInnerLoop::off_map(const Vec4& p_a, const Vec4& p_b) const {
  std::uint8_t bits = at_relief(p_a, p_b);
  for (int i = 0; i < kNumActive; ++i)
    if (std::min(p_a[i], p_b[i]) < model_.hydraulics.tank_pressure) bits |= static_cast<std::uint8_t>(1u << i);
  return bits;
}

void ValveInnerLoop::column_stiffness(int i, double q, double& s_a, double& s_b) const {
  const HydraulicGeometry& g = model_.geometry;
  const HydraulicParameters& h = model_.hydraulics;
  double v_a = h.swing_volume, v_b = h.swing_volume;
  if (i > 0) {
    const double stroke = std::clamp(q - model_.q_min[i], 0.0, model_.q_max[i] - model_.q_min[i]);
    v_a = h.dead_volume + g.area_a[i] * stroke;
    v_b = h.dead_volume + g.area_b[i] * (model_.q_max[i] - model_.q_min[i] - stroke);
  }
  s_a = g.area_a[i] * g.area_a[i] / v_a;
  s_b = g.area_b[i] * g.area_b[i] / v_b;
}

Vec4 ValveInnerLoop::hydraulic_stiffness(const Vec4& q) const {
  Vec4 k;
  for (int i = 0; i < kNumActive; ++i) {
    double s_a = 0, s_b = 0;
    column_stiffness(i, q[i], s_a, s_b);
    k[i] = model_.hydraulics.bulk_modulus * (s_a + s_b);
  }
  return k;
}

double ValveInnerLoop::opening_for(int i, double u, double q, double p_a, double p_b) const {
  return opening_for(i, u, q, p_a, p_b, p_a, p_b);
}

double ValveInnerLoop::opening_for(int i, double u, double q, double p_a, double p_b, double level_a,
                                   double level_b) const {
  if (u == 0) return 0;
  const HydraulicGeometry& g = model_.geometry;
  const HydraulicParameters& h = model_.hydraulics;
  const bool extend = u > 0;
  // Meter-in: the compensator holds the margin across it unless the load nears the main relief.
  const double load = extend ? p_a : p_b;
  const double drop_in = std::min(h.load_sensing_margin, model_.main_relief() - load);
  const double k_in = extend ? g.meter_in_a[i] : g.meter_in_b[i];
  const double area_in = extend ? g.area_a[i] : g.area_b[i];
  const double flow_in = k_in * orifice(drop_in, h.laminar_pressure);
  if (!(flow_in > 0)) return extend ? 2.0 : -2.0;  // stalled at the relief: fully open
  const double p_in = extend ? p_a : p_b, p_out = extend ? p_b : p_a;
  const double k_out = extend ? g.meter_out_b[i] : g.meter_out_a[i];
  const double area_out = extend ? g.area_b[i] : g.area_a[i];
  const double flow_out = k_out * orifice(p_out - h.tank_pressure, h.laminar_pressure);
  // Resisting load: one spool meters both sides. At a held force the two chambers' pressures move
  // together (A_in dp_in = A_out dp_out), so the piston runs at the mean of the speeds the meter-in
  // and the meter-out pass at this opening, weighted by the columns' stiffnesses s = A^2 / V:
  //   qd = a (s_in w_in + s_out w_out) / (s_in + s_out),  w = flow per unit opening / area,
  // which also makes the force loop's dF/dt = K_h (u - qd) exact. Steady, w_out = w_in (the outlet
  // settles where its meter-out passes the piston's flow) and this is the meter-in's map. Where a
  // motion starts or turns the outlet is not there yet, and the meter-in's map alone left the oil
  // that pressurises both chambers to the position correction: most of the bucket's error with no
  // soil (docs/control.md). w_out is taken at the outlet's level (update_levels), not its reading.
  double s_a = 0, s_b = 0;
  column_stiffness(i, q, s_a, s_b);
  const double s_in = extend ? s_a : s_b, s_out = extend ? s_b : s_a;
  const double flow_out_level = k_out * orifice((extend ? level_b : level_a) - h.tank_pressure, h.laminar_pressure);
  const double speed_per_opening = (s_in * flow_in / area_in + s_out * flow_out_level / area_out) / (s_in + s_out);
  double a = std::abs(u) / speed_per_opening;
  // Meter-out: an overrunning load drives the return flow through it faster than the meter-in fills
  // the other side. Only while that side is down at the make-up (within the laminar pressure of
  // tank): a resisting load keeps it above, and then the meter-in alone sets the speed. Between the
  // two (up to three laminar pressures above tank) the openings blend, so the map has no step.
  if (flow_out > 0) {
    const double metered_out = std::min(a, area_out * std::abs(u) / flow_out);
    const double w = std::clamp((p_in - h.tank_pressure - h.laminar_pressure) / (2 * h.laminar_pressure), 0.0, 1.0);
    a = w * a + (1 - w) * metered_out;
  }
  return extend ? a : -a;
}

const ValveCommand& ValveInnerLoop::from_force(const Vec4& force_desired, const Vec4& v_ff, const Vec4& q,
                                               const Vec4& p_a, const Vec4& p_b) {
  command_.force = measured_force(p_a, p_b);
  const Vec4 k_h = hydraulic_stiffness(q);
  const double ti = settings_.force_integral_time;
  for (int i = 0; i < kNumActive; ++i) {
    const double proportional = (force_desired[i] - command_.force[i]) / (k_h[i] * settings_.force_time_constant);
    // The integral holds while the valve is fully open or the function is in position (anti-windup).
    const bool frozen = ((command_.limited | in_position_) >> i) & 1u;
    if (ti > 0 && !frozen) force_integral_[i] += proportional * period_ / ti;
    if ((in_position_ >> i) & 1u) force_integral_[i] = 0;
    command_.velocity[i] = v_ff[i] + proportional + force_integral_[i];
  }
  finish(q, p_a, p_b);
  return command_;
}

const ValveCommand& ValveInnerLoop::from_velocity(const Vec4& velocity, const Vec4& q, const Vec4& p_a,
                                                  const Vec4& p_b) {
  command_.force = measured_force(p_a, p_b);
  command_.velocity = velocity;
  finish(q, p_a, p_b);
  return command_;
}

// The pressures the map's meter-out term reads. The valve's flows move m = V_A p_A / A_A + V_B p_B / A_B,
// the piston's motion does not (it compresses one side as it relieves the other): m is taken as
// measured, the force F = A_A p_A - A_B p_B low-passed at a fifth of the force loop's bandwidth (as
// position_gain's default). The measured outlet pressure itself carries the oil column's ringing;
// read directly, the map cancelled the meter-out's damping of it (the flow law's boom rang to its
// relief lifting out of stiff clay on a 14 degree slope: worst error 6.4 -> 12.5 mm).
void ValveInnerLoop::update_levels(const Vec4& q, const Vec4& p_a, const Vec4& p_b) {
  const Vec4& f = command_.force;
  if (!level_primed_) force_slow_ = f;
  else force_slow_ += level_alpha_ * (f - force_slow_);
  level_primed_ = true;
  const HydraulicGeometry& g = model_.geometry;
  for (int i = 0; i < kNumActive; ++i) {
    double s_a = 0, s_b = 0;
    column_stiffness(i, q[i], s_a, s_b);
    const double aa = g.area_a[i], ab = g.area_b[i];
    const double va = aa * aa / s_a, vb = ab * ab / s_b;
    const double m = va * p_a[i] / aa + vb * p_b[i] / ab;
    level_b_[i] = (m - va * force_slow_[i] / (aa * aa)) / (va * ab / (aa * aa) + vb / ab);
    level_a_[i] = (force_slow_[i] + ab * level_b_[i]) / aa;
  }
}

void ValveInnerLoop::finish(const Vec4& q, const Vec4& p_a, const Vec4& p_b) {
  ValveCommand& c = command_;
  update_levels(q, p_a, p_b);
  c.limited = 0;
  c.demanded_flow = 0;
  Vec4 spool;
  const double band = settings_.opening_band;
  for (int i = 0; i < kNumActive; ++i) {
    if ((in_position_ >> i) & 1u) c.velocity[i] = 0;
    // A correction in a hold (a function back under control after it was in position) starts no
    // faster than the judgement's filter follows: at hold_window / hold_filter_time the filtered error
    // lags the true one by at most a window, so the function is centred again with its true error
    // between the pose and the window, not past the pose. Asked for faster, the force loop's step on
    // resuming (the law's force against the one the leakage left) lurched the boom at 20-30 mm/s and
    // its reaction threw the arm, centred with its bore side at tank, by 2-5 mm (docs/control.md).
    // A correction that has not moved its function back towards the pose (its error, read unfiltered
    // so that the motion is seen at once, a quarter window below where the correction began) within
    // hold_filter_time is released from the limit: a small flow that the leakage absorbs before the
    // pressure reaches breakaway (the swing on a slope) would otherwise never move it; a cylinder's
    // pressure reaches breakaway in about a tenth of that. Flagged as limited: the laws' integrators
    // hold while the stage passes less than they ask.
    const bool correcting = holding_ && (((settled_ & ~in_position_) >> i) & 1u) && hold_speed_[i] > 0;
    if (!correcting) {
      correction_time_[i] = 0;
      correction_start_[i] = hold_error_[i];
    } else {
      if (std::abs(raw_error_[i]) > std::abs(correction_start_[i]) - 0.25 * settings_.hold_window[i])
        correction_time_[i] += period_;
      if (correction_time_[i] <= settings_.hold_filter_time && std::abs(c.velocity[i]) > hold_speed_[i]) {
        c.velocity[i] = std::copysign(hold_speed_[i], c.velocity[i]);
        c.limited |= static_cast<std::uint8_t>(1u << i);
      }
    }
    double a = std::isfinite(c.velocity[i]) ? opening_for(i, c.velocity[i], q[i], p_a[i], p_b[i], level_a_[i], level_b_[i]) : 0.0;
    if (std::abs(a) >= 1) {
      a = a > 0 ? 1.0 : -1.0;
      c.limited |= static_cast<std::uint8_t>(1u << i);
    }
    c.opening[i] = a;
    // Dead-zone inverse, continuous: linear from 0 to the band's edge, then z + (1 - z)|a|.
    const double z = a >= 0 ? model_.hydraulics.dead_zone_extend[i] : model_.hydraulics.dead_zone_retract[i];
    const double m = std::abs(a);
    const double s = m == 0 ? 0.0 : m >= band ? z + (1 - z) * m : (z + (1 - z) * band) * m / band;
    spool[i] = a >= 0 ? s : -s;
    // The meter-in flow this opening asks of the pumps (at the margin).
    const double k_in = a >= 0 ? model_.geometry.meter_in_a[i] : model_.geometry.meter_in_b[i];
    c.demanded_flow += k_in * m * orifice(model_.hydraulics.load_sensing_margin, model_.hydraulics.laminar_pressure);
  }
  c.pump_limited = c.demanded_flow > model_.hydraulics.pump_flow;
  c.spool = spool_lead_.apply(spool);
  for (int i = 0; i < kNumActive; ++i) {
    c.pilot_a[i] = std::max(c.spool[i], 0.0) * model_.hydraulics.pilot_full_stroke;
    c.pilot_b[i] = std::max(-c.spool[i], 0.0) * model_.hydraulics.pilot_full_stroke;
  }
}

}  // namespace exc::control
