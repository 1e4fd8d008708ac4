// The hydraulic machine (sim_plant/hydraulics.hpp), each test against evidence from outside the code:
// closed forms of orifice flow and pressure build-up, the oil column's natural frequency, the flow
// sharing's stated rule with the machine file's areas and speeds, a relief's static balance, the
// make-up valve's static balance, the spool's first-order response, and the plant's energy balance.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/allocation_counter.hpp"
#include "model/closed_chain.hpp"
#include "plant_scenes.hpp"
#include "sim_plant/flow_sharing.hpp"
#include "model/machine_reader.hpp"

using namespace exc;
using namespace exc::plant;

namespace {

const Vec4 kMid(0.0, 2.2, 2.8, 2.0);  // a mid-stroke q_a

// The reference machine with spools that jump to the command and open from zero and without
// internal leakage and dry friction, so that a test sees the orifices and chambers alone (their closed
// forms leave leakage out: tests/plant/test_friction_leakage.cpp has its own).
Machine open_spools() {
  Machine m = reference_machine();
  m.hydraulics = without_dry_friction_and_leakage(m.hydraulics);
  m.hydraulics.valve_time_constant = 0;
  m.hydraulics.dead_zone_extend.setZero();
  m.hydraulics.dead_zone_retract.setZero();
  return m;
}

ActuatorCommand valve(const Vec4& opening) {
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  c.value = opening;
  return c;
}

// Zero crossings from + to - of a sampled signal, linearly interpolated in time.
std::vector<double> downward_crossings(const std::vector<double>& x, double dt) {
  std::vector<double> t;
  for (std::size_t k = 1; k < x.size(); ++k)
    if (x[k - 1] > 0 && x[k] <= 0) t.push_back(dt * (k - 1 + x[k - 1] / (x[k - 1] - x[k])));
  return t;
}

}  // namespace

TEST_CASE("plant/hydraulics: a blocked cylinder fills along the closed forms of the compensated meter-in and the orifices") {
  // Boom valve fully open, piston held. Bore side: the compensator holds the metering drop at the
  // margin, so the inflow is the speed-limit flow Q = A v_max and p rises linearly, beta Q / V,
  // until p = p_relief - margin; then the drop is p_relief - p: turbulent,
  // sqrt(p_relief - p) = sqrt(margin) - beta K (t - t1) / (2 V), then laminar below 0.2 MPa,
  // p_relief - p = p_lam exp(-beta K (t - t2) / (V sqrt(p_lam))). Rod side: drains to tank through
  // the meter-out, K_out = A_B v_max / sqrt(5 MPa), turbulent then laminar the same way.
  const Machine m = open_spools();
  const HydraulicParameters& p = m.hydraulics;
  HydraulicCircuit c(m);
  c.reset(kMid, Vec4::Zero());
  const double beta = p.bulk_modulus, margin = p.load_sensing_margin, lam = p.laminar_pressure;
  const double relief = p.main_relief_pressure, tank = p.tank_pressure;
  const double A = M_PI / 4 * 0.120 * 0.120 * 2, Ab = M_PI / 4 * (0.120 * 0.120 - 0.085 * 0.085) * 2;
  const double V = p.dead_volume + A * (kMid[1] - m.boom.min_length);
  const double Vb = p.dead_volume + Ab * (m.boom.max_length - kMid[1]);
  const double Q = A * m.boom.max_speed, K = Q / std::sqrt(margin);
  const double Kout = Ab * m.boom.max_speed / std::sqrt(p.valve_pressure_drop);
  const double pa0 = c.pressure_a()[1], pb0 = c.pressure_b()[1];
  REQUIRE(pb0 - tank > lam);  // the rod side starts in the turbulent range
  const double t1 = (relief - margin - pa0) * V / (beta * Q);
  const double t2 = t1 + 2 * V * (std::sqrt(margin) - std::sqrt(lam)) / (beta * K);
  const double tau3 = V * std::sqrt(lam) / (beta * K);
  const double tb = 2 * Vb * (std::sqrt(pb0 - tank) - std::sqrt(lam)) / (beta * Kout);
  const double taub = Vb * std::sqrt(lam) / (beta * Kout);
  auto bore = [&](double t) {
    if (t <= t1) return pa0 + beta * Q * t / V;
    if (t <= t2) {
      const double r = std::sqrt(margin) - beta * K * (t - t1) / (2 * V);
      return relief - r * r;
    }
    return relief - lam * std::exp(-(t - t2) / tau3);
  };
  auto rod = [&](double t) {
    if (t <= tb) {
      const double r = std::sqrt(pb0 - tank) - beta * Kout * t / (2 * Vb);
      return tank + r * r;
    }
    return tank + lam * std::exp(-(t - tb) / taub);
  };
  MESSAGE("phases: linear to " << t1 * 1e3 << " ms, turbulent to " << t2 * 1e3 << " ms, then tau " << tau3 * 1e3
                               << " ms; rod side turbulent to " << tb * 1e3 << " ms, then tau " << taub * 1e3 << " ms");
  c.command_opening(Vec4(0, 1, 0, 0));
  const double dt = 1e-6;
  const double checks[] = {0.5 * t1, 0.9 * t1, t1 + 0.5 * (t2 - t1), t2 + tau3, t2 + 3 * tau3};
  const double rod_checks[] = {0.5 * tb, tb + taub, tb + 2 * taub};
  double t = 0, highest = 0;
  const double t_end = t2 + 3 * tau3;
  int next = 0, next_rod = 0;
  for (long k = 1; t < t_end; ++k) {
    c.advance(dt, kMid, Vec4::Zero());
    t = k * dt;
    highest = std::max(highest, c.pressure_a()[1]);
    if (next < 5 && t >= checks[next] - 0.5 * dt) {
      CAPTURE(t);
      // Bore pressure to 0.1 % of its distance from the relief (backward Euler at 1 us).
      CHECK(relief - c.pressure_a()[1] == doctest::Approx(relief - bore(t)).epsilon(2e-3).scale(0));
      ++next;
    }
    if (next_rod < 3 && t >= rod_checks[next_rod] - 0.5 * dt) {
      CAPTURE(t);
      CHECK(c.pressure_b()[1] - tank == doctest::Approx(rod(t) - tank).epsilon(2e-3).scale(0));
      ++next_rod;
    }
  }
  CHECK(next == 5);
  CHECK(next_rod == 3);
  CHECK(highest <= relief);  // the main relief caps it: the meter-in's drop is gone there
  CHECK(c.report().pump_pressure[0] == doctest::Approx(relief).scale(0));
}

TEST_CASE("plant/hydraulics: a port relief caps a chamber driven from outside at p_set + A v / K_r, and the make-up refills the other") {
  // Valve closed, the bucket pushed in at 5 cm/s: the bore side's only outlet is its port relief,
  // so at steady state A v = K_r (p - p_set), K_r = pump flow / override. The rod side grows and
  // its only inlet is the make-up valve from the tank line: A_B v = K_mk (p_tank - p) / sqrt(p_lam),
  // K_mk = pump flow / sqrt(make-up drop) (laminar: 7 kPa below tank here).
  const Machine m = open_spools();
  const HydraulicParameters& p = m.hydraulics;
  HydraulicCircuit c(m);
  c.reset(kMid, Vec4::Zero());
  const double v = -0.05;
  // The bucket's areas as the machine file states them (356 kN and 184 kN at the 34.3 MPa relief:
  // bore 115 mm, rod 80 mm to within 0.2 %).
  const HydraulicGeometry g = hydraulic_geometry(m);
  const double A = g.area_a[3], Ab = g.area_b[3];
  CHECK(A == doctest::Approx(M_PI / 4 * 0.115 * 0.115).epsilon(2e-3).scale(0));
  CHECK(Ab == doctest::Approx(M_PI / 4 * (0.115 * 0.115 - 0.080 * 0.080)).epsilon(2e-3).scale(0));
  const HydraulicParameters& h = p;
  double highest = 0, lowest = 1e9;
  for (int k = 0; k < 3000; ++k) {
    c.advance(1e-3, kMid, Vec4(0, 0, 0, v));
    highest = std::max(highest, c.pressure_a()[3]);
    lowest = std::min(lowest, c.pressure_b()[3]);
  }
  const double expected = h.port_relief_pressure + A * -v * h.relief_override / h.pump_flow;
  CHECK(c.pressure_a()[3] == doctest::Approx(expected).epsilon(1e-9).scale(0));
  CHECK(highest <= expected * (1 + 1e-9));  // backward Euler: no overshoot on the way up
  const double below_tank = Ab * -v * std::sqrt(p.laminar_pressure) * std::sqrt(h.makeup_pressure_drop) / h.pump_flow;
  CHECK(p.tank_pressure - c.pressure_b()[3] == doctest::Approx(below_tank).epsilon(1e-6).scale(0));
  CHECK(lowest >= h.vapour_pressure);
  CHECK(c.report().relief_flow[3] == doctest::Approx(A * -v).epsilon(1e-9).scale(0));
  CHECK(c.report().makeup_flow[3] == doctest::Approx(Ab * -v).epsilon(1e-6).scale(0));
  CHECK(c.report().cavitation_substeps == 0);
  CHECK(c.report().relief_substeps > 0);
}

TEST_CASE("plant/hydraulics: a stall against the end stop holds the bore side at the main relief, no higher, and makes no energy") {
  // The bucket valve fully open into the bucket's end stop: the pump's pressure limit (the main
  // relief, 34.3 MPa) is what the bore side reaches and keeps, the rod side drains to tank. Resting
  // on the stop, the 356 kN it pushes with does no work: the energy balance stays flat to the
  // splitting error of the arm and boom still ringing from the impact (tens of J). Clamping the
  // bucket's coordinate alone let the force accelerate the joints coupled to it: the watchdog
  // stopped that plant for energy growth (> 500 J) within 0.6 s of the impact.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  Plant p(t.scene());
  const Machine& m = p.scene().machine;
  const double relief = p.scene().machine.hydraulics.main_relief_pressure;
  double highest = 0, at_rest = 0, drift = 0;
  for (int k = 1; k <= 3000; ++k) {
    const PlantStatus st = p.step(valve(Vec4(0, 0, 0, 1)));
    REQUIRE_MESSAGE(st.ok(), std::string(st.text()));
    highest = std::max(highest, p.state().pressure_a[3]);
    if (k == 1000) at_rest = p.state().energy_error;
    if (k > 1000) drift = std::max(drift, std::abs(p.state().energy_error - at_rest));
  }
  const PlantState& s = p.state();
  MESSAGE("bucket stalled at " << s.q_a[3] << " m: bore side " << s.pressure_a[3] * 1e-6 << " MPa (highest "
                               << highest * 1e-6 << "), rod side " << s.pressure_b[3] * 1e-6 << " MPa; impact "
                               << s.end_stop_loss << " J, balance moved " << drift << " J over the 2 s stall");
  CHECK(s.q_a[3] == doctest::Approx(m.bucket.max_length).scale(0));
  CHECK(highest <= relief);
  CHECK(s.pressure_a[3] == doctest::Approx(relief).epsilon(1e-3).scale(0));
  CHECK(s.pressure_b[3] == doctest::Approx(p.scene().machine.hydraulics.tank_pressure).epsilon(1e-2).scale(0));
  CHECK(s.hydraulics.pump_pressure[0] == doctest::Approx(relief).scale(0));
  CHECK(s.end_stop_loss > 0);
  CHECK(drift < 30.0);
}

TEST_CASE("plant/hydraulics: a blocked cylinder's oil column rings at omega_n = sqrt(beta / m (A_a^2 / V_a + A_b^2 / V_b))") {
  // The boom cylinders carry a 20 t mass (no gravity; a constant outside load the chambers hold),
  // valves closed; the plant's scheme: effort from the pressures at the step's start, symplectic
  // Euler for the mass, backward Euler for the chambers.
  const Machine m = open_spools();
  const HydraulicParameters& p = m.hydraulics;
  HydraulicCircuit c(m);
  Vec4 q = kMid;
  const double load = 2e5, mass = 2e4, h = 1e-4;
  c.reset(q, Vec4(0, load, 0, 0));
  const double A = c.area_a()[1], Ab = c.area_b()[1];
  const double Va = p.dead_volume + A * (q[1] - m.boom.min_length), Vb = p.dead_volume + Ab * (m.boom.max_length - q[1]);
  const double omega = std::sqrt(p.bulk_modulus / mass * (A * A / Va + Ab * Ab / Vb));
  double v = 1e-3;
  std::vector<double> vs;
  for (int k = 0; k < 20000; ++k) {
    const double f = c.effort()[1] - load;
    v += h * f / mass;
    q[1] += h * v;
    c.advance(h, q, Vec4(0, v, 0, 0));
    vs.push_back(v);
  }
  const std::vector<double> t = downward_crossings(vs, h);
  REQUIRE(t.size() > 10);
  const double period = (t.back() - t.front()) / static_cast<double>(t.size() - 1);
  MESSAGE("boom oil column with 20 t: " << 2 * M_PI / period / (2 * M_PI) << " Hz, closed form " << omega / (2 * M_PI) << " Hz");
  CHECK(2 * M_PI / period == doctest::Approx(omega).epsilon(1e-3).scale(0));
  CHECK(c.report().makeup_flow[1] == 0);  // the ringing stayed inside the chambers' pressures
}

TEST_CASE("plant/hydraulics: the swing motor's oil column in the plant rings at sqrt(beta D^2 (1/V_A + 1/V_B) / I)") {
  // The whole plant: the swing given a small speed, every valve closed; I from the model's mass
  // matrix (eq. 17), D the swing's displacement (torque limit over relief pressure).
  // The closed form is the oil spring's alone: without the swing's breakaway torque (6.6 kN m) the
  // 0.002 rad/s start sticks within the first cycle, and its motor's leakage would bleed the spring.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.qd_a = "[0.002, 0, 0, 0]";
  Scene scene = t.scene();
  scene.machine.hydraulics = without_dry_friction_and_leakage(scene.machine.hydraulics);
  Plant plant(scene);
  Workspace ws(plant.model());
  REQUIRE(update_closed_chain(plant.model(), ws, plant.state().q_a, Vec4::Zero()).ok());
  Mat4 M;
  mass_matrix(plant.model(), ws, M);
  const Machine& m = plant.scene().machine;
  const double D = m.swing.max_torque / m.relief_pressure, V = plant.scene().machine.hydraulics.swing_volume;
  const double omega = std::sqrt(plant.scene().machine.hydraulics.bulk_modulus * D * D * (2.0 / V) / M(0, 0));
  std::vector<double> speed;
  for (int k = 0; k < 8000; ++k) {
    REQUIRE(plant.step(valve(Vec4::Zero())).ok());
    speed.push_back(plant.state().qd_a[0]);
  }
  const std::vector<double> tc = downward_crossings(speed, 1e-3);
  REQUIRE(tc.size() >= 3);
  const double period = (tc.back() - tc.front()) / static_cast<double>(tc.size() - 1);
  MESSAGE("swing oil column: " << 1 / period << " Hz, closed form " << omega / (2 * M_PI) << " Hz (I = " << M(0, 0)
                               << " kg m^2)");
  CHECK(2 * M_PI / period == doctest::Approx(omega).epsilon(5e-3).scale(0));
}

TEST_CASE("plant/hydraulics: flow sharing: functions demanding more than the pumps all slow by pump flow / demand, the total is the pumps' flow") {
  const Machine m = open_spools();
  const HydraulicParameters& p = m.hydraulics;
  const double pump = p.pump_flow;  // 439 L/min
  // Alone, each fully open function takes its speed-limit flow (machine file: pump flow / area).
  const double boom = M_PI / 4 * 0.120 * 0.120 * 2 * m.boom.max_speed;
  const double arm = M_PI / 4 * 0.135 * 0.135 * m.arm.max_speed;
  const double swing = m.swing.max_torque / m.relief_pressure * m.swing.max_speed;
  auto flows = [&](const Vec4& opening) {
    HydraulicCircuit c(m);
    c.reset(kMid, Vec4::Zero());
    c.command_opening(opening);
    c.advance(1e-6, kMid, Vec4::Zero());
    return c.report();
  };
  const HydraulicReport b = flows(Vec4(0, 1, 0, 0)), a = flows(Vec4(0, 0, 1, 0)), s = flows(Vec4(1, 0, 0, 0));
  CHECK(b.meter_in_flow[1] == doctest::Approx(boom).epsilon(2e-3).scale(0));  // areas from the rounded machine limits
  CHECK(a.meter_in_flow[2] == doctest::Approx(arm).epsilon(2e-3).scale(0));
  CHECK(s.meter_in_flow[0] == doctest::Approx(swing).epsilon(1e-9).scale(0));
  CHECK(b.flow_scale[0] == 1);
  // Together: 2 x ~434 L/min asked of 439 L/min.
  const HydraulicReport ba = flows(Vec4(0, 1, 1, 0));
  const double ratio = pump / (b.meter_in_flow[1] + a.meter_in_flow[2]);
  MESSAGE("boom + arm ask " << (b.meter_in_flow[1] + a.meter_in_flow[2]) * 60000 << " L/min of " << pump * 60000
                             << ": each gets " << ratio * 100 << " %");
  CHECK(ba.meter_in_flow[1] == doctest::Approx(ratio * b.meter_in_flow[1]).epsilon(1e-9).scale(0));
  CHECK(ba.meter_in_flow[2] == doctest::Approx(ratio * a.meter_in_flow[2]).epsilon(1e-9).scale(0));
  CHECK(ba.meter_in_flow[1] + ba.meter_in_flow[2] == doctest::Approx(pump).epsilon(1e-9).scale(0));
  CHECK(ba.pump_flow.sum() == doctest::Approx(pump).epsilon(1e-9).scale(0));
  CHECK(ba.pump_flow[0] == doctest::Approx(ba.pump_flow[1]).scale(0));  // merged: each pump half
  CHECK(ba.flow_scale[0] == doctest::Approx(ratio).scale(0));
  // Three functions at part opening: the same factor for every one of them.
  const HydraulicReport three = flows(Vec4(0.8, 0.6, -0.5, 0));
  const HydraulicReport s8 = flows(Vec4(0.8, 0, 0, 0)), b6 = flows(Vec4(0, 0.6, 0, 0)), a5 = flows(Vec4(0, 0, -0.5, 0));
  const double demand = s8.meter_in_flow[0] + b6.meter_in_flow[1] + a5.meter_in_flow[2];
  REQUIRE(demand > pump);
  CHECK(three.meter_in_flow[0] / s8.meter_in_flow[0] == doctest::Approx(pump / demand).scale(0));
  CHECK(three.meter_in_flow[1] / b6.meter_in_flow[1] == doctest::Approx(pump / demand).scale(0));
  CHECK(three.meter_in_flow[2] / a5.meter_in_flow[2] == doctest::Approx(pump / demand).scale(0));
  CHECK(three.meter_in_flow.sum() == doctest::Approx(pump).scale(0));
  // Split pumps: boom and bucket share pump 0's half, the arm has pump 1's half to itself.
  Machine split = m;
  split.hydraulics.pumps_merged = false;
  split.hydraulics.pump_of = {1, 0, 1, 0};
  HydraulicCircuit c(split);
  c.reset(kMid, Vec4::Zero());
  c.command_opening(Vec4(0, 1, 1, 1));
  c.advance(1e-6, kMid, Vec4::Zero());
  const HydraulicReport& r = c.report();
  CHECK(r.meter_in_flow[1] + r.meter_in_flow[3] == doctest::Approx(pump / 2).scale(0));
  CHECK(r.meter_in_flow[2] == doctest::Approx(pump / 2).scale(0));
  CHECK(r.pump_flow[0] == doctest::Approx(pump / 2).scale(0));
  CHECK(r.pump_flow[1] == doctest::Approx(pump / 2).scale(0));
  CHECK(r.meter_in_flow[1] / r.meter_in_flow[3] == doctest::Approx(b.meter_in_flow[1] / flows(Vec4(0, 0, 0, 1)).meter_in_flow[3]).scale(0));
}

TEST_CASE("plant/hydraulics: the flow-sharing rule's two functions") {
  CHECK(flow_share_scale(0.5, 1.0) == 1.0);
  CHECK(flow_share_scale(4.0, 1.0) == 0.25);
  CHECK(load_sensing_pressure(true, 10e6, 0.3e6, 2e6, 34.3e6) == 12e6);
  CHECK(load_sensing_pressure(true, 33e6, 0.3e6, 2e6, 34.3e6) == 34.3e6);
  CHECK(load_sensing_pressure(false, 33e6, 0.3e6, 2e6, 34.3e6) == doctest::Approx(2.3e6).scale(0));
}

TEST_CASE("plant/hydraulics: in the plant, boom and arm together both slow by pump flow / demand") {
  // Boom up and arm in, valves fully open: 434 + 429 L/min asked of 439. Each function's mean speed
  // is then its share of the flow over its bore area, v = s v_max with s = 439 / 863: measured from
  // the mechanism's displacement over a second (the oil columns ring about that mean), against
  // the machine file's areas and speeds.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.q_a = "[0.5, 1.9, 3.0, 1.8]";  // the second reference pose: the boom low, the arm with room to go
  Plant plant(t.scene());
  const Machine& m = plant.scene().machine;
  const double pump = plant.scene().machine.hydraulics.pump_flow;
  const double q_boom = m.boom.max_force / m.relief_pressure * m.boom.max_speed;
  const double q_arm = m.arm.max_force / m.relief_pressure * m.arm.max_speed;
  const double s = pump / (q_boom + q_arm);
  Vec4 q0 = Vec4::Zero();
  bool always_saturated = true;
  for (int k = 1; k <= 1400; ++k) {
    REQUIRE(plant.step(valve(Vec4(0, 1, 1, 0))).ok());
    if (k == 400) q0 = plant.state().q_a;
    if (k > 400) {
      always_saturated = always_saturated && plant.state().hydraulics.flow_scale[0] < 1;
      CHECK(plant.state().hydraulics.meter_in_flow.sum() == doctest::Approx(pump).epsilon(1e-9).scale(0));
    }
  }
  const Vec4 mean = plant.state().q_a - q0;  // over 1 s
  MESSAGE("boom " << mean[1] << " m/s (alone " << m.boom.max_speed << "), arm " << mean[2] << " m/s (alone "
                  << m.arm.max_speed << "); shared factor " << s);
  CHECK(always_saturated);
  // The sensors carry the swing motor's and the pumps' pressures besides the cylinders'.
  const SensorReading& r = plant.sensors();
  CHECK(r.pump_pressure == plant.state().hydraulics.pump_pressure);
  CHECK(r.pump_pressure[0] > plant.state().pressure_a[1]);  // the highest load + the margin
  CHECK(r.swing_pressure == Vec2(plant.state().pressure_a[0], plant.state().pressure_b[0]));
  CHECK(mean[1] == doctest::Approx(s * m.boom.max_speed).epsilon(0.03).scale(0));
  CHECK(mean[2] == doctest::Approx(s * m.arm.max_speed).epsilon(0.03).scale(0));
}

TEST_CASE("plant/hydraulics: pumps that lose flow (the fault campaign's pump_loss) deliver their share: the boom alone slows to it, and speeds up again when the flow is back") {
  // The boom alone, its valve fully open, asks 434 L/min of the pumps' 439: unsaturated. With 30 %
  // of the flow left (Plant::set_pump_flow_scale) the pumps deliver 132 L/min, all of it to the boom,
  // whose mean speed is then that flow over its bore area.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.q_a = "[0.5, 1.9, 3.0, 1.8]";
  Plant plant(t.scene());
  const Machine& m = plant.scene().machine;
  const double pump = m.hydraulics.pump_flow;
  const double bore = m.boom.max_force / m.relief_pressure;
  plant.set_pump_flow_scale(0.3);
  Vec4 q0 = Vec4::Zero();
  for (int k = 1; k <= 1400; ++k) {
    REQUIRE(plant.step(valve(Vec4(0, 1, 0, 0))).ok());
    if (k == 400) q0 = plant.state().q_a;
    if (k > 400) {
      CHECK(plant.state().hydraulics.flow_scale[0] < 1);
      CHECK(plant.state().hydraulics.meter_in_flow.sum() == doctest::Approx(0.3 * pump).epsilon(1e-9).scale(0));
    }
  }
  const double slow = plant.state().q_a[1] - q0[1];  // m over 1 s
  MESSAGE("boom at 30 % of the pumps' flow: " << slow << " m/s (flow / bore area " << 0.3 * pump / bore << ")");
  CHECK(slow == doctest::Approx(0.3 * pump / bore).epsilon(0.03).scale(0));
  plant.set_pump_flow_scale(1);
  for (int k = 1; k <= 400; ++k) REQUIRE(plant.step(valve(Vec4(0, 1, 0, 0))).ok());
  CHECK(plant.state().hydraulics.flow_scale[0] == 1);
  CHECK(plant.state().hydraulics.meter_in_flow[1] > 0.9 * pump);
}

TEST_CASE("plant/hydraulics: a fast boom-down (overrunning load) refills the rod side from tank with no pressure below vapour") {
  // Lowering, the boom's weight drives it faster than the pump fills the rod side (the meter-out
  // from the loaded bore side sets the speed): without the make-up valves the rod side would fall
  // below zero. Evidence that the load overran: the rod side swept more than the meter-in gave.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  Plant plant(t.scene());
  const Machine& m = plant.scene().machine;
  const double floor = plant.scene().machine.hydraulics.vapour_pressure;
  const double Ab = -m.boom.min_force / m.relief_pressure;
  const double l0 = plant.state().q_a[1];
  double lowest = 1e9, metered = 0, refilled = 0, fastest = 0;
  int k = 0;
  for (; k < 3000 && plant.state().q_a[1] > 1.85; ++k) {
    REQUIRE(plant.step(valve(Vec4(0, -1, 0, 0))).ok());
    const PlantState& s = plant.state();
    lowest = std::min({lowest, s.pressure_a.minCoeff(), s.pressure_b.minCoeff()});
    fastest = std::min(fastest, s.qd_a[1]);
    metered += 1e-3 * s.hydraulics.meter_in_flow[1];
    refilled += 1e-3 * s.hydraulics.makeup_flow[1];
  }
  const double swept = Ab * (l0 - plant.state().q_a[1]);
  MESSAGE("boom down to " << plant.state().q_a[1] << " m in " << k << " ms, fastest " << fastest << " m/s (limit "
                          << m.boom.max_speed << "); rod side swept " << swept * 1e3 << " L, metered in "
                          << metered * 1e3 << " L, refilled from tank " << refilled * 1e3 << " L; lowest pressure "
                          << lowest * 1e-6 << " MPa");
  CHECK(swept > 1.1 * metered);
  // The speed is the meter-out's: A v = K_out sqrt(p_A - p_tank), K_out = A v_max / sqrt(5 MPa).
  const PlantState& s = plant.state();
  const double p_tank = plant.scene().machine.hydraulics.tank_pressure, drop = plant.scene().machine.hydraulics.valve_pressure_drop;
  CHECK(-s.qd_a[1] == doctest::Approx(m.boom.max_speed * std::sqrt((s.pressure_a[1] - p_tank) / drop)).epsilon(0.02).scale(0));
  CHECK(refilled > 0.1 * metered);  // overrunning: the make-up valves carried a real part of it
  CHECK(lowest >= floor);
  CHECK(plant.state().hydraulics.cavitation_substeps == 0);
}

namespace {

struct EnergyRun {
  double worst_error = 0;  // J, largest |energy_error| over the run
  double pump_work = 0;    // J
  PlantState last;
  HydraulicEnergy energy;
  double mechanism = 0;    // J, change of kinetic + potential energy
};

// All four functions moving (sinusoidal valve commands, saturating the pumps at times), the bucket
// in loam, gravity; 4 s at 1 ms cycles with the given integrator step.
EnergyRun energy_run(double step) {
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.terrain = "height: 1.9";
  t.soil = "preset: loam";
  t.step = step;
  Plant plant(t.scene());
  EnergyRun r;
  const double mech0 = plant.energy();
  for (int k = 0; k < 4000; ++k) {
    const double s = k * 1e-3;
    const Vec4 opening(0.6 * std::sin(2.0 * s), 0.8 * std::sin(1.3 * s + 0.5), -0.7 * std::sin(1.7 * s),
                       0.9 * std::sin(2.3 * s + 1.0));
    REQUIRE(plant.step(valve(opening)).ok());
    r.worst_error = std::max(r.worst_error, std::abs(plant.state().energy_error));
  }
  r.last = plant.state();
  r.energy = r.last.hydraulics.energy;
  r.pump_work = r.energy.pump_work;
  r.mechanism = plant.energy() - mech0;
  return r;
}

}  // namespace

TEST_CASE("plant/hydraulics: energy balance with the hydraulics: pump work in, losses out, oil compression stored") {
  // E_mech + E_oil - E0 = pump work + tank line - losses + soil work (HydraulicEnergy), with the
  // mechanism's energy computed from the links' twists and heights, not from the circuit, and the
  // end stops' impacts counted as losses. What is left is the splitting error of holding the effort
  // over each step: first order in the step.
  const EnergyRun r = energy_run(1e-3);
  const HydraulicEnergy& e = r.energy;
  // The circuit's own books close to round-off (chamber.hpp's discrete balance).
  const double circuit = e.stored - e.stored0 - (e.supplied() - e.piston_work);
  MESSAGE("4 s, four functions: pump work " << e.pump_work * 1e-3 << " kJ, losses " << e.losses() * 1e-3
                                            << " kJ (meter-in " << e.meter_in_loss * 1e-3 << ", meter-out "
                                            << e.meter_out_loss * 1e-3 << ", relief " << e.relief_loss * 1e-3
                                            << ", make-up " << e.makeup_loss * 1e-3 << ", leakage "
                                            << e.leakage_loss * 1e-3 << "), friction " << r.last.friction_loss * 1e-3
                                            << " kJ, oil stored "
                                            << (e.stored - e.stored0) << " J, soil " << r.last.soil_work * 1e-3
                                            << " kJ, mechanism " << r.mechanism * 1e-3 << " kJ; energy error "
                                            << r.last.energy_error << " J (worst " << r.worst_error
                                            << " J), circuit books " << circuit << " J; saturated "
                                            << r.last.hydraulics.saturated_substeps << " ms");
  CHECK(std::abs(circuit) < 1e-9 * e.pump_work);
  CHECK(e.pump_work > 1e5);                          // a real run: > 100 kJ through the pumps
  CHECK(r.last.hydraulics.saturated_substeps > 0);    // and the pumps saturated on the way
  CHECK(r.last.hydraulics.relief_substeps > 0);       // and a relief opened
  CHECK(r.last.end_stop_events > 0);                  // the cylinders hit their stops (impacts in the books)
  CHECK(e.leakage_loss > 0);                          // the machine's internal leakage in the books
  CHECK(r.last.friction_loss > 0);                    // and its friction, viscous and dry
  CHECK(r.worst_error < 1e-3 * r.pump_work);          // stated tolerance: 0.1 % of the pump work
  // First order: a quarter of the step, about a quarter of the error.
  const EnergyRun fine = energy_run(0.25e-3);
  MESSAGE("worst energy error at 1 ms " << r.worst_error << " J, at 0.25 ms " << fine.worst_error << " J");
  CHECK(fine.worst_error < 0.35 * r.worst_error);
}

TEST_CASE("plant/hydraulics: a chamber pressure above the highest relief + margin stops the plant naming it") {
  // Every relief set to 8 MPa while the boom needs 10.4 MPa to hold the reference pose: the boom
  // sinks through its port relief, whose override at that flow exceeds a 0.1 MPa check margin.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.checks += ", pressure_check_margin: 0.1e6";
  Scene scene = t.scene();
  scene.machine.hydraulics.supply_pressure = 8e6;
  scene.machine.hydraulics.port_relief_pressure = 8e6;
  scene.machine.hydraulics.swing_relief_pressure = 8e6;
  Plant p(scene);
  PlantStatus st;
  for (int k = 0; k < 500 && st.ok(); ++k) st = p.step(valve(Vec4::Zero()));
  REQUIRE(st.failure == PlantFailure::pressure_range);
  MESSAGE(std::string(st.text()));
  CHECK(std::string(st.text()).find("boom bore-side pressure") != std::string::npos);
  CHECK(std::string(st.text()).find("outside [0, 8.1] MPa") != std::string::npos);
  // With the default 5 MPa margin the same sag is only the relief doing its work.
  scene.checks.pressure_check_margin = 5e6;
  Plant q(scene);
  for (int k = 0; k < 500; ++k) REQUIRE(q.step(valve(Vec4::Zero())).ok());
  CHECK(q.state().hydraulics.relief_substeps > 0);
  CHECK(q.state().q_a[1] < q.scene().q_a0[1] - 0.01);
  // NaN in a pressure is caught as non-finite state.
  CheckInputs in;
  MechanicalState ms;
  IntegratorSettings is;
  const Vec4 bad(0, NAN, 0, 0), good = Vec4::Constant(1e6);
  in.state = &ms;
  in.integrator = &is;
  in.pressure_a = &good;
  in.pressure_b = &bad;
  in.pressure_max = 40e6;
  PlantStatus s2;
  CHECK_FALSE(run_plant_checks(CheckSettings{}, in, s2));
  CHECK(s2.failure == PlantFailure::non_finite);
}

TEST_CASE("plant/hydraulics: dead zones: no motion below the threshold, motion above it, per direction") {
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  Scene scene = t.scene();
  scene.machine.hydraulics.dead_zone_extend[1] = 0.2;
  scene.machine.hydraulics.dead_zone_retract[1] = 0.3;
  auto run = [&](double opening) {
    Plant p(scene);
    for (int k = 0; k < 500; ++k) REQUIRE(p.step(valve(Vec4(0, opening, 0, 0))).ok());
    return p.state();
  };
  const PlantState closed = run(0);
  // Inside the dead zone the spool moves but the metering stays shut: the same run as closed.
  for (double o : {0.19, -0.29}) {
    CAPTURE(o);
    const PlantState s = run(o);
    CHECK(s.q_a == closed.q_a);
    CHECK(s.pressure_a == closed.pressure_a);
    CHECK(s.hydraulics.meter_in_flow[1] == 0);
    CHECK(s.spool[1] != 0);
  }
  const PlantState out = run(0.23), in = run(-0.33);
  MESSAGE("boom after 0.5 s: closed " << closed.q_a[1] << ", 0.23 " << out.q_a[1] << ", -0.33 " << in.q_a[1]);
  CHECK(out.q_a[1] > closed.q_a[1] + 1e-3);
  CHECK(in.q_a[1] < closed.q_a[1] - 1e-3);
  // 0.23 opens past 0.2 but -0.23 does not pass 0.3: the two directions differ.
  const PlantState in_small = run(-0.23);
  CHECK(in_small.q_a == closed.q_a);
}

TEST_CASE("plant/hydraulics: the spool follows its lag (63 % at tau) from an opening or from pilot pressures") {
  const Machine m = reference_machine();
  const HydraulicParameters& p = m.hydraulics;
  REQUIRE(p.valve_time_constant == 0.03);  // the default: pilot-operated mobile valves, 30-100 ms
  const double k63 = 1 - std::exp(-1.0);
  HydraulicCircuit a(m), b(m);
  a.reset(kMid, Vec4::Zero());
  b.reset(kMid, Vec4::Zero());
  a.command_opening(Vec4(1, -0.5, 0.25, 0));
  // 5 MPa on swing A: full stroke; 2.5 MPa on boom B: half stroke retracting; 1 and 2 MPa on the
  // arm's two ends: -0.2.
  b.command_pilots(Vec4(5e6, 0, 1e6, 0), Vec4(0, 2.5e6, 2e6, 0));
  for (int k = 0; k < 30; ++k) {
    a.advance(1e-3, kMid, Vec4::Zero());
    b.advance(1e-3, kMid, Vec4::Zero());
  }
  CHECK((a.spool() - Vec4(1, -0.5, 0.25, 0) * k63).norm() < 1e-12);
  CHECK((b.spool() - Vec4(1, -0.5, -0.2, 0) * k63).norm() < 1e-12);
  // Through the plant, pilot commands drive the machine like openings do.
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  Plant pv(t.scene()), pp(t.scene());
  ActuatorCommand pilot;
  pilot.mode = ActuatorCommand::pilot;
  pilot.pilot_a = Vec4(0, 4e6, 0, 0);
  for (int k = 0; k < 300; ++k) {
    REQUIRE(pv.step(valve(Vec4(0, 0.8, 0, 0))).ok());
    REQUIRE(pp.step(pilot).ok());
  }
  CHECK((pp.state().q_a - pv.state().q_a).norm() < 1e-12);
  CHECK(pp.state().q_a[1] > pv.scene().q_a0[1] + 0.01);
}

TEST_CASE("plant/hydraulics: a command of a kind the actuators cannot use stops the plant with a message") {
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  Plant hydraulic(t.scene());
  ActuatorCommand effort;
  effort.value = hydraulic.hold_effort();
  PlantStatus st = hydraulic.step(effort);
  CHECK(st.failure == PlantFailure::bad_command);
  MESSAGE(std::string(st.text()));
  CHECK(std::string(st.text()).find("effort commands for actuators.fidelity hydraulic") != std::string::npos);
  CHECK(hydraulic.step(valve(Vec4::Zero())).failure == PlantFailure::bad_command);  // and it stays stopped
  for (const char* fidelity : {"fidelity: limited", "fidelity: ideal"}) {
    t.actuators = fidelity;
    for (ActuatorCommand::Mode mode : {ActuatorCommand::valve, ActuatorCommand::pilot}) {
      Plant p(t.scene());
      ActuatorCommand c;
      c.mode = mode;
      st = p.step(c);
      CAPTURE(std::string(fidelity));
      CHECK(st.failure == PlantFailure::bad_command);
      CHECK(std::string(st.text()).find("take efforts") != std::string::npos);
      CHECK(p.state().cycle == 0);
    }
  }
  t.actuators = "fidelity: hydraulic";
  Plant p(t.scene());
  ActuatorCommand c;
  c.mode = ActuatorCommand::pilot;
  c.pilot_b[2] = 6e6;
  st = p.step(c);
  CHECK(st.failure == PlantFailure::bad_command);
  CHECK(std::string(st.text()).find("pilot pressure outside 0..5 MPa") != std::string::npos);
}

TEST_CASE("plant/hydraulics: parameters outside their ranges are refused naming the field and the range") {
  // The ranges are the machine file's (declared once by its reader); a machine changed in C++ is held
  // to them when the circuit is built.
  struct Case {
    void (*edit)(HydraulicParameters&);
    const char* field;
    const char* reason;
  };
  const Case cases[] = {
      {[](HydraulicParameters& h) { h.pump_flow = 0; }, "hydraulics.pump_flow", "is 0 m^3/s (not from the file); allowed range [0.0001, 0.05] m^3/s"},
      {[](HydraulicParameters& h) { h.load_sensing_margin = 1e5; }, "hydraulics.load_sensing_margin", "is 100000 Pa (not from the file); allowed range [300000, 5000000] Pa"},
      {[](HydraulicParameters& h) { h.main_relief_pressure = 1e9; }, "hydraulics.main_relief_pressure", "is 1e+09 Pa (not from the file); allowed range [5000000, 6e+07] Pa"},
      {[](HydraulicParameters& h) { h.port_relief_pressure = NAN; }, "hydraulics.port_relief_pressure", "is nan Pa (not from the file); allowed range [5000000, 6e+07] Pa"},
      {[](HydraulicParameters& h) { h.swing_relief_pressure = 1e6; }, "hydraulics.swing_relief_pressure", "is 1000000 Pa (not from the file); allowed range [5000000, 6e+07] Pa"},
      {[](HydraulicParameters& h) { h.relief_override = 0; }, "hydraulics.relief_override", "is 0 Pa (not from the file); allowed range [10000, 1e+07] Pa"},
      {[](HydraulicParameters& h) { h.makeup_pressure_drop = 1e7; }, "hydraulics.makeup_pressure_drop", "is 1e+07 Pa (not from the file); allowed range [10000, 2000000] Pa"},
      {[](HydraulicParameters& h) { h.vapour_pressure = -1e6; }, "hydraulics.vapour_pressure", "is -1000000 Pa (not from the file); allowed range [-100000, 100000] Pa"},
      {[](HydraulicParameters& h) { h.pilot_full_stroke = 0; }, "hydraulics.pilot_full_stroke", "is 0 Pa (not from the file); allowed range [1000000, 1e+07] Pa"},
      {[](HydraulicParameters& h) { h.dead_zone_extend[2] = 0.95; }, "hydraulics.dead_zone_extend[2]", "is 0.95 (not from the file); allowed range [0, 0.9]"},
      {[](HydraulicParameters& h) { h.dead_zone_retract[0] = -0.1; }, "hydraulics.dead_zone_retract[0]", "is -0.1 (not from the file); allowed range [0, 0.9]"},
      {[](HydraulicParameters& h) { h.pump_of[3] = 2; }, "hydraulics.pump_of[3]", "is 2 (not from the file); allowed range [0, 1]"},
      {[](HydraulicParameters& h) { h.bulk_modulus = 1; }, "hydraulics.bulk_modulus", "is 1 Pa (not from the file); allowed range [1e+07, 5e+09] Pa"},
      {[](HydraulicParameters& h) { h.breakaway_ratio = 0.5; }, "hydraulics.breakaway_ratio", "is 0.5 (not from the file); allowed range [1, 3]"},
      {[](HydraulicParameters& h) { h.stribeck_velocity[3] = 0; }, "hydraulics.stribeck_velocity[3]", "is 0 (not from the file); allowed range [0.0001, 1]"},
      {[](HydraulicParameters& h) { h.seal_pressure_friction[1] = -1e-4; }, "hydraulics.seal_pressure_friction[1]", "is -0.0001 (not from the file); allowed range [0, 0.01]"},
      {[](HydraulicParameters& h) { h.spool_leakage[2] = -1e-14; }, "hydraulics.spool_leakage[2]", "is -1e-14 m^3/(s Pa) (not from the file); allowed range [0, 1e-09] m^3/(s Pa)"},
      {[](HydraulicParameters& h) { h.swing_drain_leakage = 1e-6; }, "hydraulics.swing_drain_leakage", "is 1e-06 m^3/(s Pa) (not from the file); allowed range [0, 1e-09] m^3/(s Pa)"},
      {[](HydraulicParameters& h) { h.tank_pressure = 0, h.vapour_pressure = 0.05e6; }, "hydraulics.vapour_pressure",
       "is 50000 Pa; must not exceed tank_pressure (0 Pa)"},
  };
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  CHECK_NOTHROW(Plant{t.scene()});
  for (const Case& c : cases) {
    Scene s = t.scene();
    c.edit(s.machine.hydraulics);
    CAPTURE(std::string(c.field));
    try {
      Plant p{s};
      FAIL("no error");
    } catch (const SettingsError& e) {
      CAPTURE(std::string(e.what()));
      CHECK(e.file() == "<embedded>");  // the machine's source
      CHECK(e.field() == c.field);
      CHECK(e.reason().find(c.reason) != std::string::npos);
    }
  }
  // The margin of the plant's pressure check is a scene check.
  t.checks = "pressure_check_margin: -1";
  CHECK_THROWS_WITH_AS(t.scene(), doctest::Contains("checks.pressure_check_margin: is -1"), std::runtime_error);
}

TEST_CASE("plant/hydraulics: the hydraulic step allocates nothing (valve and pilot commands, saturation, relief, make-up)") {
  REQUIRE(exc::app::allocation_counting_works());
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.terrain = "height: 1.9";
  t.soil = "preset: stiff_clay";
  Plant p(t.scene());
  ActuatorCommand c = valve(Vec4(1, 1, -1, 1));
  p.step(c);
  std::size_t allocations = 0;
  int steps = 0;
  {
    exc::app::AllocationCounter counter;
    exc::app::EigenNoMallocScope no_eigen_malloc;
    for (int k = 0; k < 4000; ++k) {
      if (k % 1000 == 500) {
        c.mode = ActuatorCommand::pilot;
        c.pilot_a = Vec4(5e6, 0, 3e6, 0);
        c.pilot_b = Vec4(0, 5e6, 0, 2e6);
      } else if (k % 1000 == 0) {
        c = valve(Vec4(-1, k % 2000 == 0 ? 1 : -1, 1, -1));
      }
      if (!p.step(c).ok()) break;
      ++steps;
    }
    allocations = counter.count();
  }
  MESSAGE("relief " << p.state().hydraulics.relief_substeps << " ms, saturated " << p.state().hydraulics.saturated_substeps
                    << " ms, end stops " << p.state().end_stop_events << " ms");
  CHECK(p.state().hydraulics.relief_substeps > 0);
  CHECK(p.state().hydraulics.saturated_substeps > 0);
  CHECK(p.state().end_stop_events > 0);
  CHECK(steps == 4000);
  CHECK(allocations == 0);
}
