#pragma once
// The inner loop between a control law and a hydraulic machine's valves (hydraulics.md, "How
// published automation closes the loop"). Per function i (swing motor, boom, arm, bucket):
//
//   force loop   u = v_ff + (F_d - F) / (K_h(q) T_f),  v_ff = qd_d - K_x e     (m/s; swing rad/s)
//                F = p_A A_A - p_B A_B from the measured chamber pressures (swing: D (p_A - p_B)),
//                K_h = beta (A_A^2 / V_A(q) + A_B^2 / V_B(q)), the oil columns' stiffness. With u the
//                flow the valve passes per piston area, dF/dt = K_h (u - qd): with v_ff = qd the
//                force follows F_d with the time constant T_f; v_ff is the desired velocity (the
//                flow feedforward), equal to qd while the machine tracks, with the position error's
//                correction K_x e (position_gain) that a stiff oil column needs.
//   (a flow law, FlowPositionControl, gives u directly and skips the force loop)
//   orifice map  the opening that moves the piston at u: per unit opening the pressure-compensated
//                meter-in passes w_in = K_in f(min(margin, p_relief - p_load)) / A_in and the
//                meter-out w_out = K_out f(p_out - p_tank) / A_out; at a held force the piston runs at
//                their mean weighted by the columns' A^2 / V, so a = |u| (s_in + s_out) /
//                (s_in w_in + s_out w_out) (w_out at the outlet's level: the pressurising of both
//                chambers where a motion starts or turns). For an overrunning load the meter-out
//                a_out = A_out |u| / (K_out f(p_out - p_tank)) holds it back; a = min(a, a_out), at
//                most 1 (the valve's limit: flagged, anti-windup).
//   dead zone    spool s = sign(a) (z + (1 - z) |a|) with the nominal dead zone z of the direction,
//                linear through zero over |a| < opening_band (a narrow band above the command's
//                noise: any continuous inverse leaves the valve shut for |a| below about the band, a
//                dead band in the loop, so the band stays small).
//   in position  while the machine holds a pose (mode hold), a function whose error is inside
//                hold_window is left with its valve centred, the load held by the closed valve as an
//                operator's machine holds it; it is corrected again once the error exceeds
//                kHoldReentry times the window, and then every other function outside its own window
//                is corrected with it (a correction's reaction throws the neighbours). Without it the dead-zone inverse and the spool's lag make a valve hunt
//                around the pose (docs/control.md: a growing limit cycle of the flow law). The error
//                both judgements read is low-passed over hold_filter_time, longer than the oil
//                columns' period (2-3 Hz): a load ringing on its closed valve (after a correction, or
//                when another function moves) does not reopen it and a correction passing through the
//                window does not centre it mid-way, while the slow creep of leakage is seen as it is.
//                The laws hold their integrators and updates on a centred function (limited()).
//                A correction (a function back under control after it was in position in this hold)
//                moves at most at hold_window / hold_filter_time, flagged as limited (its step on
//                resuming otherwise lurched a loaded boom and threw its neighbours), unless it has not
//                moved the function back within hold_filter_time (a flow the leakage absorbs).
//   spool lead   the pilot-operated spool's first-order lag T_s made to look like the shorter T_t
//                (ActuatorLagCompensator on the spool position, limits -1..1).
//   pilots       p_pilot_A = max(s, 0) p_full, p_pilot_B = max(-s, 0) p_full.
//
// f(dp) is the orifice law with its laminar branch (model/hydraulic_geometry.hpp, shared with the
// plant). Allocation-free after construction; the update calls never throw.
#include <cstdint>

#include "control/actuation/actuator_lag_compensator.hpp"
#include "model/hydraulic_geometry.hpp"
#include "model/machine.hpp"

namespace exc::control {

// The nominal hydraulic machine as the valve stage sees it: the firmware's machine file (its
// hydraulics section and the geometry derived from it, as the plant derives its own).
struct ValveLoopModel {
  HydraulicGeometry geometry;
  HydraulicParameters hydraulics;
  Vec4 q_min = Vec4::Zero(), q_max = Vec4::Zero();  // strokes (chamber volumes)
  double main_relief() const { return hydraulics.pump_pressure_limit(); }
};
ValveLoopModel valve_loop_model(const Machine& nominal);

struct ValveLoopSettings {
  double force_time_constant = 0.03;  // s, T_f: the force loop's time constant (the spool's lag, docs/control.md)
  double spool_lag_target = 0.01;     // s, T_t the spool lead aims for (0: no lead)
  // s, T_i of the force loop's integral (0: none, the default): what the proportional loop leaves of
  // a force step (7.6 % on the boom), for an outer law that commands forces. Under the
  // computed-torque laws it hands the position back to their soft gains and the dig's bucket error
  // grew 3-20x (docs/control.md), so position tracking leaves it off.
  double force_integral_time = 0;
  double opening_band = 0.002;        // opening below which the dead-zone inverse is linear
  // 1/s: the flow feedforward v_ff = qd_d - position_gain e also corrects the position, as the flow
  // law does: the force loop alone meters flow only in proportion to a force error, so a small
  // position error of a stiff oil column is left uncorrected. Default 1 / (5 T_f) (derived where the
  // controller section is read: a fifth of the force loop's bandwidth; docs/control.md).
  Vec4 position_gain = Vec4::Constant(1 / (5 * 0.03));
  // Holding a pose: |e| below which a function's valve stays centred (rad swing, m cylinders).
  Vec4 hold_window = Vec4::Constant(1e-3);
  // s: the time constant of the low-pass on the error the in-position judgement reads (above).
  double hold_filter_time = 0.25;
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, ValveLoopSettings& s) {
  v("force_time_constant", s.force_time_constant);
  v("spool_lag_target", s.spool_lag_target);
  v("force_integral_time", s.force_integral_time);
  v("opening_band", s.opening_band);
  v("position_gain", s.position_gain);
  v("hold_window", s.hold_window);
  v("hold_filter_time", s.hold_filter_time);
}

// Holding, a centred function is corrected again past this many hold windows. 1.5: the leakage's
// creep is corrected from 1.5 mm, and what a correction throws the other functions by (the links
// couple them; about 0.6 mm on the arm when the boom corrects in the dig's pose) stays inside the
// 2.5 mm holding tolerance (docs/control.md, "Holding still"; at 2 the PID's arm reached 2.65 mm
// in an hour's hold). A function corrected again takes with it every function outside its window.
inline constexpr double kHoldReentry = 1.5;

// What the valve stage sends and what it found.
struct ValveCommand {
  Vec4 velocity = Vec4::Zero();   // u: commanded flow per piston area (m/s; swing rad/s)
  Vec4 opening = Vec4::Zero();    // a: metering opening asked for, -1..1 (before the dead zone)
  Vec4 spool = Vec4::Zero();      // s: spool command after dead zone and lead, -1..1
  Vec4 pilot_a = Vec4::Zero();    // Pa on each spool's A end (extends / swings counter-clockwise)
  Vec4 pilot_b = Vec4::Zero();    // Pa on each spool's B end
  Vec4 force = Vec4::Zero();      // F measured from the pressures (N; swing N m)
  std::uint8_t limited = 0;       // bit i: the valve could not pass the flow asked for (fully open)
  double demanded_flow = 0;       // m^3/s the meter-ins ask of the pumps together
  bool pump_limited = false;      // demanded_flow above the pumps' flow: every function slows
};

class ValveInnerLoop {
 public:
  ValveInnerLoop() = default;
  // The nominal machine's hydraulics; period of the calls (s).
  ValveInnerLoop(const ValveLoopModel& model, const ValveLoopSettings& settings, double period);

  // Spool model and lead restart from the centred spool.
  void reset();
  // Each cycle before the update: holding a pose (true, with the error e = q - q_d) or moving (false).
  // Holding, a function inside its window is centred until its error exceeds kHoldReentry windows (both
  // on the error low-passed over hold_filter_time, which follows e while moving).
  void set_holding(bool holding, const Vec4& error);
  std::uint8_t in_position() const { return in_position_; }

  // Force loop: the desired efforts of the outer law, the flow feedforward v_ff, the measured
  // positions and chamber pressures (per function; swing ports first).
  const ValveCommand& from_force(const Vec4& force_desired, const Vec4& v_ff, const Vec4& q, const Vec4& p_a,
                                 const Vec4& p_b);
  // Flow law: the commanded velocity directly.
  const ValveCommand& from_velocity(const Vec4& velocity, const Vec4& q, const Vec4& p_a, const Vec4& p_b);

  // The measured effort F of each function.
  Vec4 measured_force(const Vec4& p_a, const Vec4& p_b) const;
  // Bit i: function i's measured chambers are where its valve cannot do what the map assumes: a load
  // within the load-sensing margin of the supply limit or at its port relief (the meter-in stalls,
  // the relief passes flow), or a chamber below tank pressure (the make-up valve feeds it).
  std::uint8_t off_map(const Vec4& p_a, const Vec4& p_b) const;
  // Functions with a chamber at or near its relief (bit i): oil may leave by the relief, unmetered.
  std::uint8_t at_relief(const Vec4& p_a, const Vec4& p_b) const;
  // K_h(q) of each function (N/m per m/s of flow mismatch, i.e. N/m; swing N m/rad).
  Vec4 hydraulic_stiffness(const Vec4& q) const;
  // The opening that moves function i at the velocity u at its position q and these pressures
  // (before the dead zone), unclamped; the outlet's level taken as its reading.
  double opening_for(int i, double u, double q, double p_a, double p_b) const;
  const ValveCommand& last() const { return command_; }
  const ValveLoopSettings& settings() const { return settings_; }
  const Vec4& spool_model() const { return spool_lead_.delivered(); }  // the lead's spool positions
  const Vec4& force_integral() const { return force_integral_; }

 private:
  void finish(const Vec4& q, const Vec4& p_a, const Vec4& p_b);
  // The oil columns' A_A^2 / V_A and A_B^2 / V_B of function i at position q (1/m; swing D^2 / V).
  void column_stiffness(int i, double q, double& s_a, double& s_b) const;
  // The same with the outlet's level apart from its reading (update_levels).
  double opening_for(int i, double u, double q, double p_a, double p_b, double level_a, double level_b) const;
  // The chambers' levels the map's meter-out term reads: the valve-driven part of the measured
  // pressures at the slow force (the .cpp says why).
  void update_levels(const Vec4& q, const Vec4& p_a, const Vec4& p_b);

  ValveLoopModel model_;
  ValveLoopSettings settings_;
  ActuatorLagCompensator spool_lead_;
  std::uint8_t in_position_ = 0;  // bit i: function i centred, in position
  std::uint8_t settled_ = 0;      // bit i: function i has been in position in this hold (then corrected at hold_speed_)
  bool holding_ = false;          // the machine holds a pose (set_holding)
  Vec4 hold_error_ = Vec4::Zero();  // the low-passed error the in-position judgement reads
  double hold_alpha_ = 1.0;         // its filter gain per call, 1 - exp(-period / hold_filter_time)
  double period_ = 1e-3;
  Vec4 hold_speed_ = Vec4::Zero();  // a correction's speed limit in a hold, hold_window / hold_filter_time (0: none)
  Vec4 correction_time_ = Vec4::Zero();   // s each function's correction has gone without moving it back
  Vec4 correction_start_ = Vec4::Zero();  // the filtered error where each function's correction began
  Vec4 raw_error_ = Vec4::Zero();         // this cycle's error as set_holding received it
  Vec4 force_integral_ = Vec4::Zero();  // the force loop's integral, as a flow per piston area
  double level_alpha_ = 1.0;  // the slow force's filter gain per call, 1 - exp(-period / (5 T_f))
  Vec4 level_a_ = Vec4::Zero(), level_b_ = Vec4::Zero();  // Pa, the chambers' levels (update_levels)
  Vec4 force_slow_ = Vec4::Zero();
  bool level_primed_ = false;
  ValveCommand command_;
};

}  // namespace exc::control
