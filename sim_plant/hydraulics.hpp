#pragma once
// The hydraulic machine of a 20 t excavator (hydraulics.md): two pumps with load-sensing flow
// sharing (flow_sharing.hpp), four pilot-operated main-valve spools with lag and dead zones
// (spool_valve.hpp), the boom, arm and bucket cylinders and the swing motor with their chamber
// pressures (chamber.hpp), main relief, port reliefs and anti-cavitation make-up valves.
//
// Per function i (swing, boom, arm, bucket), spool x in -1..1, metering opening a = dead-zoned |x|:
//   extending (x > 0): P -> A through the compensated meter-in, B -> T through the meter-out;
//   retracting (x < 0): P -> B, A -> T; closed (a = 0): both chambers trapped.
//   meter-in  Q_in  = s K_in a sqrt(min(margin, p_relief_main - p_load))   (s: flow-sharing factor)
//   meter-out Q_out = K_out a sqrt(p - p_tank)
//   make-up   Q_mk  = K_mk sqrt(p_tank - p) while p < p_tank
//   relief    Q_r   = K_r (p - p_setting) above the port relief's setting
//   leakage   Q_l   = C_s (p - p_tank) to tank past the centred spool (swing: plus its case drain),
//             Q_x   = C_p (p_A - p_B) across the piston (swing: cross-port), held over the substep
//   chambers  dp_A/dt = beta / V_A (Q_A - Q_x - A_A v),  dp_B/dt = beta / V_B (Q_B + Q_x + A_B v)
//   effort    F = p_A A_A - p_B A_B  (swing: T = D (p_A - p_B), D the displacement at the swing axis)
// (orifices are linear below the laminar pressure). Cylinder areas, the swing displacement and the
// valve gains are the machine's hydraulic geometry (model/hydraulic_geometry.hpp: effort limits at
// the relief pressure, speed limits); every other number is the machine file's `hydraulics:` section
// (Machine::hydraulics).
#include <array>
#include <cstdint>
#include <limits>
#include <string>

#include "model/hydraulic_geometry.hpp"
#include "model/machine.hpp"
#include "sim_plant/chamber.hpp"

namespace exc::plant {

inline constexpr int kNumPumps = 2;

// Energy bookkeeping of the circuit since reset (J). Pressures are gauge: the tank line at
// tank_pressure exchanges p_tank Q with the chambers (tank_work). With E_oil the oil's compression
// energy sum V p^2 / (2 beta), the circuit closes
//   E_oil - E_oil(0) = pump_work + tank_work + vapour_work + volume_term - losses() - piston_work
// exactly (chamber.hpp's discrete balance, trapezoidal pressures); piston_work is what the
// cylinders and the swing motor did on the machine.
struct HydraulicEnergy {
  double stored = 0, stored0 = 0;   // E_oil now and at reset
  double pump_work = 0;             // pump pressure x delivered flow
  double tank_work = 0;             // p_tank x (make-up - return flow)
  double vapour_work = 0;           // pressure x void volume (cavitation; 0 when the make-up keeps up)
  double volume_term = 0;           // p0^2 / (2 beta) dV: the linear oil spring's term for a chamber
                                    // whose volume changes (it is not a state function then)
  double meter_in_loss = 0, meter_out_loss = 0, relief_loss = 0, makeup_loss = 0;
  double leakage_loss = 0;          // internal leakage: across the pistons and to tank past the spools
  double piston_work = 0;           // sum of p dV of the moving chambers (the actuators' work on the machine)
  double losses() const { return meter_in_loss + meter_out_loss + relief_loss + makeup_loss + leakage_loss; }
  // What entered the circuit from outside the machine's mechanism, net of its losses.
  double supplied() const { return pump_work + tank_work + vapour_work + volume_term - losses(); }
};

// The circuit's state beyond the chamber pressures, for the plant's state and its checks.
struct HydraulicReport {
  Vec2 pump_pressure = Vec2::Zero();  // Pa, each pump (equal when merged)
  Vec2 pump_flow = Vec2::Zero();      // m^3/s, each pump
  Vec2 flow_scale = Vec2::Ones();     // flow-sharing factor of each pump (1: the demand is met)
  Vec4 opening = Vec4::Zero();        // signed metering opening after the dead zone (-1..1)
  Vec4 meter_in_flow = Vec4::Zero();  // m^3/s per function over the last substep
  Vec4 meter_out_flow = Vec4::Zero();
  Vec4 makeup_flow = Vec4::Zero();    // both chambers of the function together
  Vec4 relief_flow = Vec4::Zero();
  Vec4 leakage_flow = Vec4::Zero();         // to tank past the spool (swing: and the case drain), both chambers
  Vec4 piston_leakage_flow = Vec4::Zero();  // A -> B across the piston (swing: cross-port)
  std::int64_t relief_substeps = 0;     // substeps with any relief flow
  std::int64_t saturated_substeps = 0;  // substeps with a pump's demand above its flow
  std::int64_t cavitation_substeps = 0; // substeps with a chamber held at the vapour floor
  double min_pressure = 0, max_pressure = 0;  // Pa, over all chambers now
  int solver_iterations = 0;            // of the eight chamber solves in the last substep
  // The safety hardware: pilot supply and engine flow (0..1), the load-holding valves closed.
  double pilot_supply = 1, engine_flow = 1;
  double pump_line_open = 1;  // the pump-line shut-off's opening (0..1)
  bool holding_valves_closed = false;
  bool bucket_holding_valve_closed = false;
  bool swing_brake_applied = false;
  HydraulicEnergy energy;
};

// Every double of the circuit's energy terms and its report, by name, to a state visitor (the shape
// of the firmware's control::StateVisitor, which this floor does not include: the subnormal scan of
// PlantNode::scan_state, docs/floating-point.md). Held to the structs by `plant/visit_state visits
// every double of HydraulicEnergy once` and `... of HydraulicReport once`.
template <typename Visitor>
void visit_state(const HydraulicEnergy& e, Visitor& v) {
  v.visit("circuit energy stored", e.stored);
  v.visit("circuit energy stored0", e.stored0);
  v.visit("circuit energy pump_work", e.pump_work);
  v.visit("circuit energy tank_work", e.tank_work);
  v.visit("circuit energy vapour_work", e.vapour_work);
  v.visit("circuit energy volume_term", e.volume_term);
  v.visit("circuit energy meter_in_loss", e.meter_in_loss);
  v.visit("circuit energy meter_out_loss", e.meter_out_loss);
  v.visit("circuit energy relief_loss", e.relief_loss);
  v.visit("circuit energy makeup_loss", e.makeup_loss);
  v.visit("circuit energy leakage_loss", e.leakage_loss);
  v.visit("circuit energy piston_work", e.piston_work);
}

template <typename Visitor>
void visit_state(const HydraulicReport& h, Visitor& v) {
  v.visit("circuit pump_pressure", h.pump_pressure);
  v.visit("circuit pump_flow", h.pump_flow);
  v.visit("circuit flow_scale", h.flow_scale);
  v.visit("circuit metering opening", h.opening);
  v.visit("circuit meter_in_flow", h.meter_in_flow);
  v.visit("circuit meter_out_flow", h.meter_out_flow);
  v.visit("circuit makeup_flow", h.makeup_flow);
  v.visit("circuit relief_flow", h.relief_flow);
  v.visit("circuit leakage_flow", h.leakage_flow);
  v.visit("circuit piston_leakage_flow", h.piston_leakage_flow);
  v.visit("circuit min_pressure", h.min_pressure);
  v.visit("circuit max_pressure", h.max_pressure);
  v.visit("circuit pilot_supply", h.pilot_supply);
  v.visit("circuit engine_flow", h.engine_flow);
  v.visit("circuit pump_line_open", h.pump_line_open);
  visit_state(h.energy, v);
}

class HydraulicCircuit {
 public:
  HydraulicCircuit() = default;
  // Throws SettingsError naming the field when machine.hydraulics is outside its ranges. The
  // chamber pressures are integrated by `pressures` (chamber.hpp).
  explicit HydraulicCircuit(const Machine& machine, PressureMethod pressures = PressureMethod::backward_euler);

  // Chamber pressures that hold 'hold' (the lower side at twice tank pressure), spools centred and
  // free.
  void reset(const Vec4& q_a, const Vec4& hold);
  // Spool targets: a signed opening per function (-1..1) or pilot pressures on each spool end (Pa).
  void command_opening(const Vec4& opening);
  void command_pilots(const Vec4& pilot_a, const Vec4& pilot_b);
  // Fault injection: the spool of `function` (0 swing .. 3 bucket) stuck at `spool` (-1..1) whatever
  // its target, until release_spool(). Nothing else changes: the pumps feed it and its chambers fill
  // and drain through the opening it is stuck at, with every other valve centred too.
  void stick_spool(int function, double spool);
  void release_spool() { stuck_ = -1; }
  int stuck_function() const { return stuck_; }  // -1: none
  // The spools a healthy valve would have: spool() with a stuck one's replaced by where its command
  // would have taken it from where it stuck (the same lag, pilots and dead zone). The onset of a stuck
  // spool's disagreement is judged against it (the stop requirement's R1, docs/safety.md).
  Vec4 healthy_spool() const {
    Vec4 s = spool_;
    if (stuck_ >= 0) s[stuck_] = free_spool_;
    return s;
  }
  // Fault injection (the fault campaign): the pumps deliver `scale` of pump_flow from now on.
  void set_pump_flow_scale(double scale) { pump_flow_scale_ = scale; }
  // The machine's safety hardware (docs/safety.md). Pilot cut-off: with the supply off, the pilot
  // supply decays with hydraulics.pilot_cutoff_time and every spool's target with it (they spring to
  // centre; a stuck spool keeps its opening); back on, it recovers likewise. Engine stop: the pumps'
  // flow falls linearly to zero over hydraulics.engine_rundown_time (and rises so on a restart).
  // Load-holding valves (hydraulics.load_holding_valves): closed while the supply is below half.
  // The emergency stop's safety solenoids (de-energised: false): the pump-line shut-off's flow
  // falls to zero over hydraulics.pump_shutoff_time, the load-holding valves (and the bucket's, when
  // fitted) close hydraulics.holding_valve_close_time after the drop, the swing brake is dumped at
  // once; energised again, the shut-off reopens likewise and the valves and the brake follow the
  // pilot supply.
  void set_pilot_supply(bool on) { pilot_on_ = on; }
  void set_engine_running(bool on) { engine_on_ = on; }
  void set_safety_solenoids(bool energised) { solenoids_on_ = energised; }
  // The swing lock: the swing's parking brake applied on any latched stop (a controlled one too),
  // as a machine's safety controller drops its swing-lock solenoid once the machine is stopped.
  void set_swing_lock(bool on) { swing_lock_ = on; }
  double pilot_supply() const { return pilot_; }   // 0..1 of the pilot pressure
  double engine_flow() const { return engine_; }   // 0..1 of the pumps' rated flow
  double pump_line_open() const { return shutoff_; }  // 0..1: the pump-line shut-off's opening
  bool holding_valves_closed() const {
    return hp_.load_holding_valves && (pilot_ < 0.5 || solenoid_off_time_ >= hp_.holding_valve_close_time);
  }
  bool bucket_holding_valve_closed() const {
    return hp_.bucket_holding_valve && solenoid_off_time_ >= hp_.holding_valve_close_time;
  }
  bool swing_brake_applied() const { return hp_.swing_brake_torque > 0 && (pilot_ < 0.5 || !solenoids_on_ || swing_lock_); }

  // Advance spools, pumps and chambers over dt; q_a is the position at the end, qd_a the velocity
  // over the substep (the piston sweeps A qd_a dt).
  void advance(double dt, const Vec4& q_a, const Vec4& qd_a);

  Vec4 effort() const { return g_.area_a.cwiseProduct(p_a_) - g_.area_b.cwiseProduct(p_b_); }
  const Vec4& spool() const { return spool_; }
  const Vec4& pressure_a() const { return p_a_; }
  const Vec4& pressure_b() const { return p_b_; }
  const Vec4& area_a() const { return g_.area_a; }  // m^2; swing: displacement m^3/rad
  const Vec4& area_b() const { return g_.area_b; }
  const Vec4& meter_in_gain() const { return g_.meter_in_a; }  // fully open, m^3/s/sqrt(Pa), into A (extend)
  const HydraulicReport& report() const { return report_; }
  const HydraulicParameters& parameters() const { return hp_; }
  double main_relief() const { return main_relief_; }
  double tank_pressure() const { return hp_.tank_pressure; }
  // The range the plant's check holds the chamber pressures to: from the vapour floor to the highest
  // relief setting (plus the scene's checks.pressure_check_margin).
  double pressure_floor() const { return hp_.vapour_pressure; }
  double highest_relief() const;
  double stored_energy(const Vec4& q_a) const;

 private:
  double volume_a(int i, const Vec4& q_a) const;
  double volume_b(int i, const Vec4& q_a) const;
  void update_pump_report(const Vec4& load_a, const Vec4& load_b);
  double piston_leakage_flow(double coefficient, double dp, double volume_a, double volume_b, double dt) const;

  HydraulicParameters hp_;
  PressureMethod pressures_ = PressureMethod::backward_euler;
  int stuck_ = -1;
  double stuck_spool_ = 0;
  double free_spool_ = 0;  // the stuck function's spool had it not stuck
  double main_relief_ = 0;
  Vec4 q_min_ = Vec4::Zero(), q_max_ = Vec4::Zero();
  HydraulicGeometry g_;  // areas and fully open orifice gains (model/hydraulic_geometry.hpp)
  Vec4 relief_setting_ = Vec4::Zero();
  double k_relief_ = 0, k_makeup_ = 0;
  double pump_flow_scale_ = 1;
  bool pilot_on_ = true, engine_on_ = true, solenoids_on_ = true, swing_lock_ = false;
  double pilot_ = 1, engine_ = 1, shutoff_ = 1;
  double solenoid_off_time_ = -1;  // s since the safety solenoids dropped; negative while energised
  Vec4 target_ = Vec4::Zero(), spool_ = Vec4::Zero(), p_a_ = Vec4::Zero(), p_b_ = Vec4::Zero();
  Vec4 v_a_ = Vec4::Zero(), v_b_ = Vec4::Zero();  // chamber volumes at the end of the last substep
  // The two first-order lags' gains (pilot supply, spools) for the step `lag_dt_`: the plant's step
  // is fixed, so the two exp() are taken once, not every substep (NaN: none yet).
  double lag_dt_ = std::numeric_limits<double>::quiet_NaN(), pilot_lag_gain_ = 0, spool_lag_gain_ = 0;
  HydraulicReport report_;
};

}  // namespace exc::plant
