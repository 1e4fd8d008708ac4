// The valve stage (valve_inner_loop.hpp) against closed forms: the measured effort from the
// pressures, the oil columns' stiffness, the inverse orifice map (meter-in, near the relief, the
// overrunning load's meter-out), the dead-zone inverse, saturation, pilots, the spool lead against
// an independently integrated spool, the force loop's law, the pump flow, and the flow law.
#include <doctest/doctest.h>

#include <cmath>

#include "app/allocation_counter.hpp"
#include "control/controller_config.hpp"
#include "control/laws/flow_position_control.hpp"
#include "control/actuation/valve_inner_loop.hpp"

using namespace exc;
using namespace exc::control;

namespace {

constexpr double kPeriod = 1e-3;

// A round-number machine so the expectations below are hand-computable.
ValveLoopModel simple_model() {
  ValveLoopModel m;
  HydraulicGeometry& g = m.geometry;
  HydraulicParameters& h = m.hydraulics;
  g.area_a = Vec4(1e-4, 0.02, 0.015, 0.01);
  g.area_b = Vec4(1e-4, 0.01, 0.008, 0.005);
  const Vec4 speed(1.0, 0.3, 0.5, 0.7);  // the fully open meter-in passes A * speed at the margin
  h.load_sensing_margin = 2e6;
  h.laminar_pressure = 0.2e6;
  h.tank_pressure = 0.3e6;
  h.main_relief_pressure = 34e6;
  h.supply_pressure = 0;
  for (int i = 0; i < 4; ++i) {
    g.meter_in_a[i] = g.area_a[i] * speed[i] / std::sqrt(2e6);
    g.meter_in_b[i] = g.area_b[i] * speed[i] / std::sqrt(2e6);
    g.meter_out_a[i] = g.area_a[i] * speed[i] / std::sqrt(5e6);  // at a 5 MPa drop
    g.meter_out_b[i] = g.area_b[i] * speed[i] / std::sqrt(5e6);
  }
  h.dead_zone_extend = Vec4(0.1, 0.15, 0.2, 0.25);
  h.dead_zone_retract = Vec4(0.12, 0.17, 0.22, 0.27);
  m.q_min = Vec4(-10, 1.0, 1.0, 1.0);
  m.q_max = Vec4(10, 2.0, 2.0, 2.0);
  h.bulk_modulus = 1e9;
  h.dead_volume = 0.002;
  h.swing_volume = 0.01;
  h.pump_flow = 0.007;
  h.valve_time_constant = 0.03;
  h.pilot_full_stroke = 5e6;
  return m;
}

// The stage's proportional parts alone: no spool lead, no force integral.
ValveLoopSettings no_lead() {
  ValveLoopSettings s;
  s.spool_lag_target = 0;
  s.force_integral_time = 0;
  return s;
}

const Vec4 kMid(0, 1.5, 1.5, 1.5);
const Vec4 kLowP = Vec4::Constant(1e6);  // a modest load on either side: the meter-in governs
// Both chambers where a steady motion holds them: the outlet's meter-out passes what the meter-in
// does (5 MPa across it, the round machine's rating), so the map is the meter-in's in either direction.
const Vec4 kSteadyP = Vec4::Constant(0.3e6 + 5e6);

}  // namespace

TEST_CASE("firmware/valve stage measures each function's effort as p_A A_A - p_B A_B") {
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  const Vec4 pa(10e6, 12e6, 3e6, 20e6), pb(2e6, 1e6, 9e6, 0.5e6);
  const Vec4 f = loop.measured_force(pa, pb);
  CHECK(f[0] == doctest::Approx(1e-4 * 10e6 - 1e-4 * 2e6));  // swing: D (p_A - p_B), 800 N m
  CHECK(f[1] == doctest::Approx(0.02 * 12e6 - 0.01 * 1e6));  // 230 kN
  CHECK(f[2] == doctest::Approx(0.015 * 3e6 - 0.008 * 9e6)); // -27 kN: pulling
  CHECK(f[3] == doctest::Approx(0.01 * 20e6 - 0.005 * 0.5e6));
}

TEST_CASE("firmware/valve stage's oil-column stiffness is beta (A_A^2/V_A + A_B^2/V_B) at the stroke") {
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  const Vec4 q(0.3, 1.25, 1.5, 1.9);
  const Vec4 k = loop.hydraulic_stiffness(q);
  CHECK(k[0] == doctest::Approx(1e9 * 2 * 1e-8 / 0.01));
  // boom at a quarter stroke: V_A = 0.002 + 0.02 * 0.25, V_B = 0.002 + 0.01 * 0.75
  CHECK(k[1] == doctest::Approx(1e9 * (0.02 * 0.02 / 0.007 + 0.01 * 0.01 / 0.0095)));
  CHECK(k[3] == doctest::Approx(1e9 * (0.01 * 0.01 / (0.002 + 0.01 * 0.9) + 0.005 * 0.005 / (0.002 + 0.005 * 0.1))));
}

namespace {

// The piston's speed per unit opening at a held force: the meter-in fills one chamber, the meter-out
// empties the other, and a held force moves both pressures together (A_in dp_in = A_out dp_out), so
// with dp/dt = beta/V (flow - A qd) on each side qd is the stiffness-weighted (A^2/V) mean of the
// speeds the two orifices pass. Written out here from the chamber equations, not from the stage.
double held_force_speed(const ValveLoopModel& m, int i, bool extend, double q, double p_in, double p_out) {
  const HydraulicGeometry& g = m.geometry;
  const HydraulicParameters& h = m.hydraulics;
  const double area_in = extend ? g.area_a[i] : g.area_b[i], area_out = extend ? g.area_b[i] : g.area_a[i];
  const double stroke = q - m.q_min[i], full = m.q_max[i] - m.q_min[i];
  const double v_a = i == 0 ? h.swing_volume : h.dead_volume + g.area_a[i] * stroke;
  const double v_b = i == 0 ? h.swing_volume : h.dead_volume + g.area_b[i] * (full - stroke);
  const double v_in = extend ? v_a : v_b, v_out = extend ? v_b : v_a;
  const double drop_in = std::min(h.load_sensing_margin, h.main_relief_pressure - p_in);
  const double w_in = (extend ? g.meter_in_a[i] : g.meter_in_b[i]) * std::sqrt(drop_in) / area_in;
  const double w_out = (extend ? g.meter_out_b[i] : g.meter_out_a[i]) * std::sqrt(p_out - h.tank_pressure) / area_out;
  const double s_in = area_in * area_in / v_in, s_out = area_out * area_out / v_out;
  return (s_in * w_in + s_out * w_out) / (s_in + s_out);
}

}  // namespace

TEST_CASE("firmware/valve stage's orifice map passes the asked flow through the compensated meter-in once the outlet's pressure is the motion's") {
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  // The outlet's pressure where its meter-out passes the same speed as the meter-in (5 MPa across
  // it, the round machine's rating): the steady motion, the meter-in's map alone.
  const double steady_out = m.hydraulics.tank_pressure + 5e6;
  for (int i = 0; i < 4; ++i) {
    // Extending at 40 % of the speed limit through the meter-in into A at the 2 MPa margin.
    const double u_ext = 0.4 * std::sqrt(2e6) * m.geometry.meter_in_a[i] / m.geometry.area_a[i];
    const double a = loop.opening_for(i, u_ext, kMid[i], kLowP[i], steady_out);
    CHECK(m.geometry.meter_in_a[i] * a * std::sqrt(2e6) == doctest::Approx(m.geometry.area_a[i] * u_ext));
    CHECK(a == doctest::Approx(0.4));
    // Retracting: into B.
    const double b = loop.opening_for(i, -0.25 * std::sqrt(2e6) * m.geometry.meter_in_b[i] / m.geometry.area_b[i], kMid[i],
                                      steady_out, kLowP[i]);
    CHECK(b == doctest::Approx(-0.25));
  }
  CHECK(loop.opening_for(1, 0.0, kMid[1], 5e6, 5e6) == 0.0);
}

TEST_CASE("firmware/valve stage opens wider while the outlet's pressure is below the motion's: the chambers' pressurising") {
  // At the start of a motion the outlet is near tank: its meter-out passes less than the meter-in
  // at the same opening, and the piston runs at the two speeds' stiffness-weighted mean. The stage
  // opens so that this mean, not the meter-in's speed, is the speed asked (the meter-in alone would
  // leave the oil that pressurises the chambers to the position loop).
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  for (int i = 0; i < 4; ++i) {
    for (const double q : {1.2, 1.5, 1.8}) {
      for (const double p_out : {1e6, 2e6, 4e6, 8e6}) {
        CAPTURE(i);
        CAPTURE(q);
        CAPTURE(p_out);
        const double u = 0.05;
        const double a = loop.opening_for(i, u, q, kLowP[i], p_out);
        CHECK(a * held_force_speed(m, i, true, q, kLowP[i], p_out) == doctest::Approx(u));
        const double b = loop.opening_for(i, -u, q, p_out, kLowP[i]);
        CHECK(-b * held_force_speed(m, i, false, q, kLowP[i], p_out) == doctest::Approx(u));
        // Wider than the meter-in's map below the steady outlet pressure (5.3 MPa), narrower above.
        const double meter_in_only = m.geometry.area_a[i] * u / (m.geometry.meter_in_a[i] * std::sqrt(2e6));
        if (p_out < 5.3e6) CHECK(a > meter_in_only);
        else CHECK(a < meter_in_only);
      }
    }
  }
}

TEST_CASE("firmware/valve stage opens wider when the load nears the main relief (less drop across the meter-in)") {
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  const double u = 0.1;  // m/s on the boom
  const double p_out = 5.3e6;
  const double nominal = loop.opening_for(1, u, kMid[1], 1e6, p_out);
  // 0.5 MPa left below the 34 MPa main relief: the meter-in sees 0.5 MPa instead of 2 MPa.
  const double near = loop.opening_for(1, u, kMid[1], 33.5e6, p_out);
  CHECK(nominal * held_force_speed(m, 1, true, kMid[1], 1e6, p_out) == doctest::Approx(u));
  CHECK(near * held_force_speed(m, 1, true, kMid[1], 33.5e6, p_out) == doctest::Approx(u));
  CHECK(near > 1.2 * nominal);
  // At the relief the function stalls: the stage asks for the whole valve and says so.
  ValveInnerLoop stalled(m, no_lead(), kPeriod);
  Vec4 pa = kLowP;
  pa[1] = 34e6;
  const ValveCommand& c = stalled.from_velocity(Vec4(0, u, 0, 0), kMid, pa, kLowP);
  CHECK(c.opening[1] == 1.0);
  CHECK(((c.limited >> 1) & 1u) == 1u);
}

TEST_CASE("firmware/valve stage meters an overrunning load out (the filling side at the make-up)") {
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  // Boom lowering under its weight: the rod side B fills (at tank, held by the make-up), the bore
  // side A carries the load at 15 MPa and its meter-out sets the speed: A_A u = K_out,A a sqrt(dp).
  const double u = -0.1, p_a = 15e6, p_b = m.hydraulics.tank_pressure;
  const double a = loop.opening_for(1, u, kMid[1], p_a, p_b);
  CHECK(a < 0);
  CHECK(m.geometry.meter_out_a[1] * -a * std::sqrt(p_a - m.hydraulics.tank_pressure) == doctest::Approx(m.geometry.area_a[1] * 0.1));
  // The same speed against a resisting load (B well above tank): both orifices, at a held force.
  const double resisting = loop.opening_for(1, u, kMid[1], p_a, 3e6);
  CHECK(-resisting * held_force_speed(m, 1, false, kMid[1], 3e6, p_a) == doctest::Approx(0.1));
}

TEST_CASE("firmware/valve stage inverts the dead zone continuously and saturates at the valve's limit") {
  const ValveLoopModel m = simple_model();
  ValveLoopSettings s = no_lead();
  ValveInnerLoop loop(m, s, kPeriod);
  const Vec4 speed(1.0, 0.3, 0.5, 0.7);
  for (int i = 0; i < 4; ++i) {
    for (double frac : {0.05, 0.3, 0.9, -0.05, -0.3, -0.9}) {
      Vec4 u = Vec4::Zero();
      u[i] = frac * speed[i];
      const ValveCommand& c = loop.from_velocity(u, kMid, kSteadyP, kSteadyP);
      // The plant's metering opening of this spool: (|s| - z) / (1 - z) past the dead zone z.
      const double z = frac > 0 ? m.hydraulics.dead_zone_extend[i] : m.hydraulics.dead_zone_retract[i];
      const double opened = (std::abs(c.spool[i]) - z) / (1 - z);
      CHECK(opened == doctest::Approx(std::abs(frac)));
      CHECK((c.spool[i] > 0) == (frac > 0));
      CHECK(c.limited == 0);
    }
    // Inside the band the inverse runs linearly to zero: no jump to the dead zone's edge.
    Vec4 u = Vec4::Zero();
    u[i] = 1e-3 * s.opening_band * speed[i];
    const double z = m.hydraulics.dead_zone_extend[i];
    CHECK(loop.from_velocity(u, kMid, kSteadyP, kSteadyP).spool[i] ==
          doctest::Approx(1e-3 * (z + (1 - z) * s.opening_band)));
    CHECK(loop.from_velocity(Vec4::Zero(), kMid, kSteadyP, kSteadyP).spool[i] == 0.0);
    // Twice the speed limit: fully open, flagged.
    u[i] = 2 * speed[i];
    const ValveCommand& sat = loop.from_velocity(u, kMid, kSteadyP, kSteadyP);
    CHECK(sat.spool[i] == 1.0);
    CHECK(sat.limited == (1u << i));
  }
}

TEST_CASE("firmware/valve stage sends the spool command as pilot pressures on the end it opens") {
  ValveInnerLoop loop(simple_model(), no_lead(), kPeriod);
  const ValveCommand& c = loop.from_velocity(Vec4(0.5, -0.15, 0, 0.35), kMid, kSteadyP, kSteadyP);
  CHECK(c.pilot_a[0] == doctest::Approx(c.spool[0] * 5e6));
  CHECK(c.pilot_b[0] == 0.0);
  CHECK(c.pilot_a[1] == 0.0);
  CHECK(c.pilot_b[1] == doctest::Approx(-c.spool[1] * 5e6));
  CHECK(c.pilot_a[2] == 0.0);
  CHECK(c.pilot_b[2] == 0.0);
}

TEST_CASE("firmware/valve stage's force loop commands the flow that closes the force error in T_f") {
  const ValveLoopModel m = simple_model();
  ValveLoopSettings s = no_lead();
  s.force_time_constant = 0.05;
  ValveInnerLoop loop(m, s, kPeriod);
  const Vec4 pa(5e6, 8e6, 4e6, 6e6), pb(5e6, 2e6, 2e6, 1e6);
  const Vec4 force = loop.measured_force(pa, pb);
  const Vec4 step(200, 5e3, -4e3, 2e3);
  const Vec4 v_ff(0.01, 0.02, -0.03, 0.0);
  const ValveCommand& c = loop.from_force(force + step, v_ff, kMid, pa, pb);
  const Vec4 k = loop.hydraulic_stiffness(kMid);
  for (int i = 0; i < 4; ++i) CHECK(c.velocity[i] == doctest::Approx(v_ff[i] + step[i] / (k[i] * 0.05)));
  // No error, no feedforward: the valve stays shut.
  const ValveCommand& hold = loop.from_force(force, Vec4::Zero(), kMid, pa, pb);
  CHECK(hold.spool.cwiseAbs().maxCoeff() == 0.0);
}

TEST_CASE("firmware/valve stage's force integral adds the proportional flow every T_i, and holds at the valve's limit") {
  const ValveLoopModel m = simple_model();
  ValveLoopSettings s = no_lead();
  s.force_integral_time = 0.1;
  ValveInnerLoop loop(m, s, kPeriod);
  const Vec4 pa(5e6, 8e6, 4e6, 6e6), pb(5e6, 2e6, 2e6, 1e6);
  const Vec4 force = loop.measured_force(pa, pb);
  const Vec4 k = loop.hydraulic_stiffness(kMid);
  const double error = 1e3, proportional = error / (k[1] * s.force_time_constant);
  Vec4 f = force;
  f[1] += error;
  // After n cycles with the same error: u = P (1 + n dt / T_i).
  for (int n = 1; n <= 50; ++n) {
    const ValveCommand& c = loop.from_force(f, Vec4::Zero(), kMid, pa, pb);
    CHECK(c.velocity[1] == doctest::Approx(proportional * (1 + n * kPeriod / 0.1)));
  }
  // A force error the valve cannot meet opens it fully: the integral then stops growing.
  f[1] = force[1] + 1e9;
  const double first = loop.from_force(f, Vec4::Zero(), kMid, pa, pb).velocity[1];
  REQUIRE(loop.last().limited == (1u << 1));
  const double held = loop.from_force(f, Vec4::Zero(), kMid, pa, pb).velocity[1];
  CHECK(held == doctest::Approx(first).epsilon(1e-9));
}

TEST_CASE("firmware/valve stage's spool lead makes the 30 ms spool answer with its 10 ms target") {
  const ValveLoopModel m = simple_model();
  ValveLoopSettings s;
  s.spool_lag_target = 0.01;
  ValveInnerLoop lead(m, s, kPeriod);
  ValveInnerLoop plain(m, no_lead(), kPeriod);
  // The real spool: y' = (c - y) / 30 ms, integrated with 20 Euler substeps per period (independent
  // of the stage's exact exponential model).
  auto spool_step = [&](double y, double c) {
    for (int k = 0; k < 20; ++k) y += kPeriod / 20 * (c - y) / m.hydraulics.valve_time_constant;
    return y;
  };
  const Vec4 u(0, 0.3 * 0.3, 0, 0);  // boom at 30 % of its speed: spool target 0.15 + 0.85 * 0.3
  const double target = 0.15 + 0.85 * 0.3;
  double y_lead = 0, y_plain = 0, t_lead = -1, t_plain = -1;
  for (int k = 1; k <= 200; ++k) {
    y_lead = spool_step(y_lead, lead.from_velocity(u, kMid, kSteadyP, kSteadyP).spool[1]);
    y_plain = spool_step(y_plain, plain.from_velocity(u, kMid, kSteadyP, kSteadyP).spool[1]);
    if (t_lead < 0 && y_lead >= 0.632 * target) t_lead = k * kPeriod;
    if (t_plain < 0 && y_plain >= 0.632 * target) t_plain = k * kPeriod;
  }
  CHECK(t_plain == doctest::Approx(0.030).epsilon(0.05));
  CHECK(t_lead == doctest::Approx(0.010).epsilon(0.15));
  CHECK(y_lead == doctest::Approx(target).epsilon(1e-3));  // no steady-state offset
}

TEST_CASE("firmware/valve stage counts the pumps' flow the openings ask for") {
  const ValveLoopModel m = simple_model();
  ValveInnerLoop loop(m, no_lead(), kPeriod);
  const Vec4 speed(1.0, 0.3, 0.5, 0.7);
  const ValveCommand& half = loop.from_velocity(0.2 * speed, kMid, kSteadyP, kSteadyP);
  const double expected = 0.2 * (m.geometry.area_a.dot(speed));
  CHECK(half.demanded_flow == doctest::Approx(expected));
  CHECK(half.pump_limited == (expected > m.hydraulics.pump_flow));
  const ValveCommand& full = loop.from_velocity(0.99 * speed, kMid, kSteadyP, kSteadyP);
  CHECK(full.demanded_flow == doctest::Approx(0.99 * m.geometry.area_a.dot(speed)));
  CHECK(full.pump_limited);  // 0.020 m^3/s against 0.007
}

TEST_CASE("firmware/flow law passes the desired velocity plus K_p times the position error") {
  ControllerConfig config;
  config.flow.kp = Vec4(1, 2, 3, 4);
  FlowPositionControl flow(config.flow);
  ControlInput in;
  in.q = Vec4(0.1, 2.0, 2.5, 1.8);
  in.q_d = Vec4(0.15, 1.9, 2.5, 1.85);
  in.qd_d = Vec4(0.2, -0.1, 0.05, 0.0);
  const ControlOutput out = flow.update(in);
  CHECK(out.velocity_command);
  for (int i = 0; i < 4; ++i) CHECK(out.velocity[i] == doctest::Approx(in.qd_d[i] - config.flow.kp[i] * (in.q[i] - in.q_d[i])));
  CHECK(out.tau.isZero());
}

TEST_CASE("firmware/valve stage allocates nothing over 100000 cycles") {
  ValveLoopSettings s;
  ValveInnerLoop loop(simple_model(), s, kPeriod);
  double sink = 0;
  exc::app::AllocationCounter counter;
  {
    exc::app::EigenNoMallocScope no_malloc;
    for (int k = 0; k < 100000; ++k) {
      const double w = 1e-3 * k;
      const Vec4 pa = Vec4::Constant(5e6 + 1e6 * std::sin(w)), pb = Vec4::Constant(2e6);
      sink += loop.from_force(Vec4::Constant(1e4 * std::cos(w)), Vec4::Constant(0.05 * std::sin(w)), kMid, pa, pb).spool.sum();
      sink += loop.from_velocity(Vec4::Constant(0.1 * std::cos(w)), kMid, pa, pb).spool.sum();
    }
  }
  CHECK(counter.count() == 0);
  CHECK(std::isfinite(sink));
}

// Holding: a function corrected again (past kHoldReentry windows) takes with it every function outside
// its own window, whose valves are then under control while the correction's reaction throws them;
// those inside their window stay centred. The old band corrected the function alone.
TEST_CASE("firmware/valve stage: in a hold a correction takes with it the functions outside their window, and leaves those inside centred") {
  const ValveLoopModel m = simple_model();
  ValveLoopSettings s = no_lead();
  s.hold_filter_time = 0;  // the judgement reads the error itself
  ValveInnerLoop loop(m, s, kPeriod);
  const double w = s.hold_window[1];
  loop.set_holding(true, Vec4::Constant(0.5 * w));
  REQUIRE(loop.in_position() == 0x0F);
  // Every function creeps into the band: still centred (the band keeps them until kHoldReentry).
  loop.set_holding(true, Vec4(0.5 * w, 1.2 * w, 1.2 * w, 0.5 * w));
  REQUIRE(loop.in_position() == 0x0F);
  // The boom passes kHoldReentry: the boom is corrected, and the arm, in the band, with it; the swing
  // and the bucket, inside their windows, stay centred.
  loop.set_holding(true, Vec4(0.5 * w, (kHoldReentry + 0.1) * w, 1.2 * w, 0.5 * w));
  CHECK(loop.in_position() == 0x09);
  // Each is centred again once inside its own window.
  loop.set_holding(true, Vec4(0.5 * w, 1.2 * w, 0.5 * w, 0.5 * w));
  CHECK(loop.in_position() == 0x0D);
  loop.set_holding(true, Vec4(0.5 * w, 0.5 * w, 0.5 * w, 0.5 * w));
  CHECK(loop.in_position() == 0x0F);
  // A function that leaves its window while another corrects is not re-engaged until it passes
  // kHoldReentry itself or another function is corrected again.
  loop.set_holding(true, Vec4(0.5 * w, (kHoldReentry + 0.1) * w, 0.5 * w, 0.5 * w));
  CHECK(loop.in_position() == 0x0D);
  loop.set_holding(true, Vec4(0.5 * w, (kHoldReentry + 0.1) * w, 1.2 * w, 0.5 * w));
  CHECK(loop.in_position() == 0x0D);
}

// Holding: a correction (a function back under control after it was in position in this hold) moves
// no faster than hold_window / hold_filter_time, flagged as limited for the laws' anti-windup, until
// it has gone hold_filter_time without moving the function back; the approach to the pose at a
// hold's start and a moving machine are not limited. Without it a law's
// force step on resuming lurched the worn machine's boom and threw its arm past the tolerance.
TEST_CASE("firmware/valve stage: in a hold a correction moves no faster than the window over the error filter's time, flagged as limited, unless it stalls that long") {
  const ValveLoopModel m = simple_model();
  const ValveLoopSettings s = no_lead();
  REQUIRE(s.hold_filter_time > 0);
  const Vec4 limit = s.hold_window / s.hold_filter_time;
  const Vec4 fast(0.05, 0.05, -0.05, 0.05);  // rad/s, m/s: far above the limit
  REQUIRE((fast.cwiseAbs() - 2 * limit).minCoeff() > 0);
  ValveInnerLoop loop(m, s, kPeriod);
  // Moving (the path's error outside the windows; the filter follows it): not limited.
  const Vec4 outside = 3 * s.hold_window;
  loop.set_holding(false, outside);
  CHECK(loop.from_velocity(fast, kMid, kSteadyP, kSteadyP).velocity.isApprox(fast));
  // A hold's start, the functions still outside their windows: not limited.
  loop.set_holding(true, outside);
  CHECK(loop.in_position() == 0);
  CHECK(loop.from_velocity(fast, kMid, kSteadyP, kSteadyP).velocity.isApprox(fast));
  CHECK(loop.last().limited == 0);
  // In position (the filtered error settles inside the window): centred.
  for (int k = 0; k < 5000; ++k) loop.set_holding(true, Vec4::Zero());
  REQUIRE(loop.in_position() == 0x0F);
  CHECK(loop.from_velocity(fast, kMid, kSteadyP, kSteadyP).velocity.isZero());
  // The leakage takes the boom past kHoldReentry windows: its correction is limited, in the direction
  // asked for; the others stay centred.
  Vec4 crept = Vec4::Zero();
  crept[1] = (kHoldReentry + 0.5) * s.hold_window[1];
  for (int k = 0; k < 5000 && loop.in_position() == 0x0F; ++k) loop.set_holding(true, crept);
  REQUIRE(loop.in_position() == 0x0D);
  const ValveCommand& c = loop.from_velocity(fast, kMid, kSteadyP, kSteadyP);
  CHECK(c.velocity[1] == doctest::Approx(limit[1]));
  CHECK(c.velocity[0] == 0.0);
  CHECK(c.velocity[2] == 0.0);
  CHECK(c.limited == 0x02);
  CHECK(loop.from_velocity(-fast, kMid, kSteadyP, kSteadyP).velocity[1] == doctest::Approx(-limit[1]));
  // Asked for less than the limit: passed as asked, not flagged.
  const Vec4 slow = 0.5 * limit;
  CHECK(loop.from_velocity(slow, kMid, kSteadyP, kSteadyP).velocity[1] == doctest::Approx(slow[1]));
  CHECK(loop.last().limited == 0);
  // A correction that has not moved the boom back within hold_filter_time (a flow the leakage
  // absorbs before the pressure reaches breakaway) is released from the limit.
  const int stalled_cycles = static_cast<int>(1.2 * s.hold_filter_time / kPeriod);
  for (int k = 0; k < stalled_cycles; ++k) {
    loop.set_holding(true, crept);
    loop.from_velocity(fast, kMid, kSteadyP, kSteadyP);
  }
  REQUIRE(loop.in_position() == 0x0D);
  CHECK(loop.last().velocity[1] == doctest::Approx(fast[1]));
  // The hold ends (the machine tracks again): no limit.
  loop.set_holding(false, crept);
  CHECK(loop.from_velocity(fast, kMid, kSteadyP, kSteadyP).velocity.isApprox(fast));
}
