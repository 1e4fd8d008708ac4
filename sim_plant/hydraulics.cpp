// The hydraulic circuit: spools -> pumps and flow sharing -> chambers, once per substep.
#include "sim_plant/hydraulics.hpp"

#include <algorithm>
#include <cmath>

#include "sim_plant/chamber.hpp"
#include "sim_plant/flow_sharing.hpp"
#include "sim_plant/spool_valve.hpp"
#include "model/machine_reader.hpp"

namespace exc::plant {

HydraulicCircuit::HydraulicCircuit(const Machine& machine, PressureMethod pressures)
    : hp_(machine.hydraulics), pressures_(pressures) {
  validate_hydraulics(machine);
  main_relief_ = hp_.pump_pressure_limit();
  q_min_ = machine.q_min();
  q_max_ = machine.q_max();
  g_ = hydraulic_geometry(machine);
  for (int i = 0; i < kNumActive; ++i) relief_setting_[i] = i == 0 ? hp_.swing_relief_pressure : hp_.port_relief_pressure;
  k_relief_ = hp_.pump_flow / hp_.relief_override;
  k_makeup_ = hp_.pump_flow / orifice_unit_flow(hp_.makeup_pressure_drop, hp_.laminar_pressure);
  reset(0.5 * (q_min_ + q_max_), Vec4::Zero());
}

double HydraulicCircuit::volume_a(int i, const Vec4& q_a) const {
  if (i == 0) return hp_.swing_volume;
  const double stroke = std::clamp(q_a[i] - q_min_[i], 0.0, q_max_[i] - q_min_[i]);
  return hp_.dead_volume + g_.area_a[i] * stroke;
}

double HydraulicCircuit::volume_b(int i, const Vec4& q_a) const {
  if (i == 0) return hp_.swing_volume;
  const double stroke = std::clamp(q_max_[i] - q_a[i], 0.0, q_max_[i] - q_min_[i]);
  return hp_.dead_volume + g_.area_b[i] * stroke;
}

double HydraulicCircuit::highest_relief() const {
  return std::max({main_relief_, hp_.port_relief_pressure, hp_.swing_relief_pressure});
}

double HydraulicCircuit::stored_energy(const Vec4& q_a) const {
  double e = 0;
  for (int i = 0; i < kNumActive; ++i)
    e += (volume_a(i, q_a) * p_a_[i] * p_a_[i] + volume_b(i, q_a) * p_b_[i] * p_b_[i]) / (2.0 * hp_.bulk_modulus);
  return e;
}

void HydraulicCircuit::reset(const Vec4& q_a, const Vec4& hold) {
  target_.setZero();
  spool_.setZero();
  stuck_ = -1;
  pilot_on_ = engine_on_ = solenoids_on_ = true;
  swing_lock_ = false;
  pilot_ = engine_ = shutoff_ = 1;
  solenoid_off_time_ = -1;
  const double low = 2.0 * hp_.tank_pressure;
  for (int i = 0; i < kNumActive; ++i) {
    const double f = hold[i];
    if (f >= 0) {
      p_b_[i] = low;
      p_a_[i] = std::clamp((f + g_.area_b[i] * low) / g_.area_a[i], hp_.tank_pressure, main_relief_);
    } else {
      p_a_[i] = low;
      p_b_[i] = std::clamp((g_.area_a[i] * low - f) / g_.area_b[i], hp_.tank_pressure, main_relief_);
    }
    v_a_[i] = volume_a(i, q_a);
    v_b_[i] = volume_b(i, q_a);
  }
  report_ = HydraulicReport{};
  report_.energy.stored = report_.energy.stored0 = stored_energy(q_a);
  update_pump_report(p_a_, p_b_);
  report_.min_pressure = std::min(p_a_.minCoeff(), p_b_.minCoeff());
  report_.max_pressure = std::max(p_a_.maxCoeff(), p_b_.maxCoeff());
}

void HydraulicCircuit::command_opening(const Vec4& opening) {
  for (int i = 0; i < kNumActive; ++i) target_[i] = spool_target_from_opening(opening[i]);
}

void HydraulicCircuit::stick_spool(int function, double spool) {
  if (stuck_ != std::clamp(function, 0, kNumActive - 1)) free_spool_ = spool_[std::clamp(function, 0, kNumActive - 1)];
  stuck_ = std::clamp(function, 0, kNumActive - 1);
  stuck_spool_ = std::clamp(spool, -1.0, 1.0);
}

void HydraulicCircuit::command_pilots(const Vec4& pilot_a, const Vec4& pilot_b) {
  for (int i = 0; i < kNumActive; ++i) target_[i] = spool_target_from_pilots(pilot_a[i], pilot_b[i], hp_.pilot_full_stroke);
}

// Pump pressures (and, by the flow sharing, the pumps' flows) from the loads of the open functions.
void HydraulicCircuit::update_pump_report(const Vec4& load_a, const Vec4& load_b) {
  bool open[kNumPumps] = {false, false};
  double highest[kNumPumps] = {hp_.tank_pressure, hp_.tank_pressure};
  for (int i = 0; i < kNumActive; ++i) {
    const double a = report_.opening[i];
    if (a == 0) continue;
    const int g = hp_.pumps_merged ? 0 : hp_.pump_of[i];
    open[g] = true;
    highest[g] = std::max(highest[g], a > 0 ? load_a[i] : load_b[i]);
  }
  for (int g = 0; g < kNumPumps; ++g) {
    const int src = hp_.pumps_merged ? 0 : g;
    report_.pump_pressure[g] =
        load_sensing_pressure(open[src], highest[src], hp_.tank_pressure, hp_.load_sensing_margin, main_relief_);
  }
}

// The flow A -> B across a piston over a substep, fixed over it (chamber.hpp): the mean flow of the
// leakage alone equalising the two trapped chambers from their starting difference dp,
// C dp (1 - exp(-lambda dt)) / (lambda dt) with lambda = beta C (1/V_A + 1/V_B). For the machine's
// coefficients lambda dt is below 1e-3 (the flow at the starting pressures to 5e-4); for any
// coefficient in range it never overshoots the equalisation, where the flow at the starting
// pressures would be unstable above lambda dt = 2.
double HydraulicCircuit::piston_leakage_flow(double coefficient, double dp, double volume_a, double volume_b,
                                             double dt) const {
  const double x = hp_.bulk_modulus * coefficient * (1.0 / volume_a + 1.0 / volume_b) * dt;
  const double mean = x < 1e-6 ? 1.0 - 0.5 * x : -std::expm1(-x) / x;
  return coefficient * dp * mean;
}

void HydraulicCircuit::advance(double dt, const Vec4& q_a, const Vec4& qd_a) {
  HydraulicReport& r = report_;
  HydraulicEnergy& e = r.energy;
  if (dt != lag_dt_) {
    pilot_lag_gain_ = spool_lag_gain(hp_.pilot_cutoff_time, dt);
    spool_lag_gain_ = spool_lag_gain(hp_.valve_time_constant, dt);
    lag_dt_ = dt;
  }
  // The safety hardware: the pilot supply (first order) and the engine's flow (linear run-down).
  pilot_ += ((pilot_on_ ? 1.0 : 0.0) - pilot_) * pilot_lag_gain_;
  engine_ = std::clamp(engine_ + (engine_on_ ? dt : -dt) / hp_.engine_rundown_time, 0.0, 1.0);
  // The emergency stop's solenoids: the pump-line shut-off (linear over its closing time) and the
  // time since they dropped, which the holding valves' closing counts.
  shutoff_ = std::clamp(shutoff_ + (solenoids_on_ ? dt : -dt) / hp_.pump_shutoff_time, 0.0, 1.0);
  solenoid_off_time_ = solenoids_on_ ? -1.0 : std::max(solenoid_off_time_, 0.0) + dt;
  const bool holding_closed = holding_valves_closed();
  const bool bucket_closed = bucket_holding_valve_closed();
  r.pilot_supply = pilot_;
  r.engine_flow = engine_;
  r.pump_line_open = shutoff_;
  r.holding_valves_closed = holding_closed;
  r.bucket_holding_valve_closed = bucket_closed;
  r.swing_brake_applied = swing_brake_applied();
  // Spools: lag toward the target (what the pilots push, as far as the supply gives them), then the
  // dead zone of the direction they moved in.
  const double lag_gain = spool_lag_gain_;
  if (stuck_ >= 0) free_spool_ = spool_lag(free_spool_, target_[stuck_] * pilot_, lag_gain);
  for (int i = 0; i < kNumActive; ++i) {
    spool_[i] = i == stuck_ ? stuck_spool_ : spool_lag(spool_[i], target_[i] * pilot_, lag_gain);
    const double a = metering_opening(spool_[i], hp_.dead_zone_extend[i], hp_.dead_zone_retract[i]);
    r.opening[i] = spool_[i] >= 0 ? a : -a;
  }
  // Pumps: each function's meter-in demand at the margin (less where its load nears the main
  // relief), summed per pump; the flow-sharing factor follows (flow_sharing.hpp). It is taken from
  // the pressures at the start of the substep.
  const int pumps = hp_.pumps_merged ? 1 : kNumPumps;
  const double pump_limit = hp_.pump_flow * pump_flow_scale_ * std::min(engine_, shutoff_) / pumps;
  double demand[kNumPumps] = {0, 0};
  for (int i = 0; i < kNumActive; ++i) {
    const double a = r.opening[i];
    if (a == 0) continue;
    const double load = a > 0 ? p_a_[i] : p_b_[i];
    const double drop = std::min(hp_.load_sensing_margin, main_relief_ - load);
    if (drop <= 0) continue;
    const double k = a > 0 ? g_.meter_in_a[i] : g_.meter_in_b[i];
    demand[hp_.pumps_merged ? 0 : hp_.pump_of[i]] += k * std::abs(a) * orifice_unit_flow(drop, hp_.laminar_pressure);
  }
  double scale[kNumPumps] = {1, 1};
  bool saturated = false;
  for (int g = 0; g < pumps; ++g) {
    scale[g] = flow_share_scale(demand[g], pump_limit);
    saturated = saturated || scale[g] < 1;
  }
  // Chambers: backward Euler each (or forward, chamber.hpp), the piston's sweep from this substep's
  // velocity.
  const auto step = pressures_ == PressureMethod::backward_euler ? &step_chamber : &step_chamber_explicit;
  Vec4 mean_a, mean_b, meter_in;
  bool relief = false, cavitation = false;
  r.solver_iterations = 0;
  for (int i = 0; i < kNumActive; ++i) {
    const double a = r.opening[i];
    const int g = hp_.pumps_merged ? 0 : hp_.pump_of[i];
    ChamberValves va;
    va.margin = hp_.load_sensing_margin;
    va.supply_limit = main_relief_;
    va.tank = hp_.tank_pressure;
    va.makeup_gain = k_makeup_;
    va.relief_setting = relief_setting_[i];
    va.relief_gain = k_relief_;
    va.laminar = hp_.laminar_pressure;
    va.leakage_gain = hp_.spool_leakage[i] + (i == 0 ? hp_.swing_drain_leakage : 0.0);
    ChamberValves vb = va;
    const double va1 = volume_a(i, q_a), vb1 = volume_b(i, q_a);
    const double across = piston_leakage_flow(hp_.piston_leakage[i], p_a_[i] - p_b_[i], va1, vb1, dt);
    va.cross_inflow = -across;
    vb.cross_inflow = across;
    if (a > 0) {
      va.meter_in_gain = scale[g] * g_.meter_in_a[i] * a;
      vb.meter_out_gain = g_.meter_out_b[i] * a;
    } else if (a < 0) {
      vb.meter_in_gain = scale[g] * g_.meter_in_b[i] * -a;
      va.meter_out_gain = g_.meter_out_a[i] * -a;
    }
    // A closed load-holding valve blocks every way out of its chamber but the port relief: the boom's
    // cap side, the arm's rod side (in-flow, through its check, stays open).
    if (holding_closed && i == 1) va.meter_out_gain = va.leakage_gain = 0;
    if (holding_closed && i == 2) vb.meter_out_gain = vb.leakage_gain = 0;
    // The bucket's double pilot-operated check, when fitted: both ports blocked.
    if (bucket_closed && i == 3) va.meter_out_gain = va.leakage_gain = vb.meter_out_gain = vb.leakage_gain = 0;
    const double swept_a = g_.area_a[i] * qd_a[i] * dt, swept_b = -g_.area_b[i] * qd_a[i] * dt;
    const ChamberStep sa = step(va, p_a_[i], va1, hp_.bulk_modulus, dt, swept_a, hp_.vapour_pressure);
    const ChamberStep sb = step(vb, p_b_[i], vb1, hp_.bulk_modulus, dt, swept_b, hp_.vapour_pressure);
    r.solver_iterations += sa.iterations + sb.iterations;
    // Energy, with trapezoidal pressures (HydraulicEnergy closes exactly with them).
    const ChamberStep* steps[2] = {&sa, &sb};
    const double p0[2] = {p_a_[i], p_b_[i]}, vol0[2] = {v_a_[i], v_b_[i]}, vol1[2] = {va1, vb1};
    const double swept[2] = {swept_a, swept_b};
    double mean[2];
    for (int c = 0; c < 2; ++c) {
      const ChamberStep& s = *steps[c];
      const double pm = 0.5 * (p0[c] + s.pressure);
      mean[c] = pm;
      e.meter_out_loss += (pm - hp_.tank_pressure) * dt * s.flows.meter_out;
      e.relief_loss += (pm - hp_.tank_pressure) * dt * s.flows.relief;
      e.makeup_loss += (hp_.tank_pressure - pm) * dt * s.flows.makeup;
      e.leakage_loss += (pm - hp_.tank_pressure) * dt * s.flows.leakage;
      e.tank_work += hp_.tank_pressure * dt * (s.flows.makeup - s.flows.meter_out - s.flows.relief - s.flows.leakage);
      e.vapour_work += pm * s.void_volume;
      e.volume_term += (vol1[c] - vol0[c]) * p0[c] * p0[c] / (2.0 * hp_.bulk_modulus);
      e.piston_work += pm * swept[c];
      relief = relief || s.flows.relief > 0;
      cavitation = cavitation || s.void_volume > 0;
    }
    e.leakage_loss += (mean[0] - mean[1]) * dt * across;
    mean_a[i] = mean[0];
    mean_b[i] = mean[1];
    meter_in[i] = sa.flows.meter_in + sb.flows.meter_in;
    r.meter_in_flow[i] = meter_in[i];
    r.meter_out_flow[i] = sa.flows.meter_out + sb.flows.meter_out;
    r.makeup_flow[i] = sa.flows.makeup + sb.flows.makeup;
    r.relief_flow[i] = sa.flows.relief + sb.flows.relief;
    r.leakage_flow[i] = sa.flows.leakage + sb.flows.leakage;
    r.piston_leakage_flow[i] = across;
    p_a_[i] = sa.pressure;
    p_b_[i] = sb.pressure;
    v_a_[i] = va1;
    v_b_[i] = vb1;
  }
  // Pump work and meter-in losses at the pump pressure of the substep's mean loads (the pump
  // pressure cancels out of the balance; this choice keeps each meter-in loss >= 0).
  update_pump_report(mean_a, mean_b);
  r.pump_flow.setZero();
  for (int i = 0; i < kNumActive; ++i) {
    const int g = hp_.pumps_merged ? 0 : hp_.pump_of[i];
    const double pm = r.opening[i] > 0 ? mean_a[i] : mean_b[i];
    e.pump_work += r.pump_pressure[g] * dt * meter_in[i];
    e.meter_in_loss += (r.pump_pressure[g] - pm) * dt * meter_in[i];
    r.pump_flow[g] += meter_in[i];
  }
  if (hp_.pumps_merged) r.pump_flow = Vec2::Constant(0.5 * r.pump_flow[0]);
  for (int g = 0; g < kNumPumps; ++g) r.flow_scale[g] = scale[hp_.pumps_merged ? 0 : g];
  // What the pumps show now, for the sensors.
  update_pump_report(p_a_, p_b_);
  e.stored = 0;
  for (int i = 0; i < kNumActive; ++i) e.stored += (v_a_[i] * p_a_[i] * p_a_[i] + v_b_[i] * p_b_[i] * p_b_[i]) / (2.0 * hp_.bulk_modulus);
  r.relief_substeps += relief ? 1 : 0;
  r.cavitation_substeps += cavitation ? 1 : 0;
  r.saturated_substeps += saturated ? 1 : 0;
  r.min_pressure = std::min(p_a_.minCoeff(), p_b_.minCoeff());
  r.max_pressure = std::max(p_a_.maxCoeff(), p_b_.maxCoeff());
}

}  // namespace exc::plant
