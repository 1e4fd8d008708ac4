// Actuators: the limited lag against its closed-form step response and its timing (no delay beyond
// the lag, checked against the swing's impulse), relief clamps, the hydraulic oil spring and spool
// lag. The hydraulic circuit's own tests are in test_hydraulics.cpp.
#include <doctest/doctest.h>

#include <cmath>

#include "model/closed_chain.hpp"
#include "plant_scenes.hpp"
#include "model/machine_reader.hpp"

using namespace exc;
using namespace exc::plant;

namespace {
const Vec4 kMid(0.0, 2.2, 2.8, 2.0);  // a mid-stroke q_a
}

TEST_CASE("plant/limited actuator follows a first-order lag (closed-form step response)") {
  const Machine m = reference_machine();
  ActuatorParameters p;
  p.fidelity = "limited";
  p.lag = 0.05;
  ActuatorModel a(m, p);
  a.reset(kMid, Vec4::Zero());
  ActuatorCommand c;
  c.value = Vec4(1000, 1e5, -5e4, 2e4);
  a.set_command(c);
  for (int k = 1; k <= 200; ++k) {
    a.advance(1e-3, kMid, Vec4::Zero());
    const double t = k * 1e-3;
    const Vec4 expected = c.value * (1.0 - std::exp(-t / 0.05));
    CHECK((a.effort(kMid) - expected).norm() < 1e-8 * c.value.norm());
  }
}

TEST_CASE("plant/limited actuator clamps efforts to the relief limits (area x 34.3 MPa)") {
  const Machine m = reference_machine();
  ActuatorParameters p;
  p.fidelity = "limited";
  p.lag = 0;
  ActuatorModel a(m, p);
  a.reset(kMid, Vec4::Zero());
  ActuatorCommand c;
  c.value = Vec4(1e6, 2e6, -2e6, 2e6);
  a.set_command(c);
  a.advance(1e-3, kMid, Vec4::Zero());
  // Two 120 mm boom cylinders at 34.3 MPa push ~776 kN; the arm's 95 mm-rod annulus pulls ~248 kN.
  const double boom_push = 2 * M_PI / 4 * 0.120 * 0.120 * 34.3e6;
  const double arm_pull = M_PI / 4 * (0.135 * 0.135 - 0.095 * 0.095) * 34.3e6;
  CHECK(a.effort(kMid)[0] == doctest::Approx(65000).scale(0));
  CHECK(a.effort(kMid)[1] == doctest::Approx(boom_push).epsilon(0.002).scale(0));
  CHECK(a.effort(kMid)[2] == doctest::Approx(-arm_pull).epsilon(0.002).scale(0));
  CHECK(a.effort(kMid)[3] == doctest::Approx(m.bucket.max_force).scale(0));
}

TEST_CASE("plant/hydraulic closed valve: the chamber pressure follows the oil spring dp/dt = -beta A v / V") {
  // Trapped oil alone: the machine's internal leakage (a laminar drain, tested on its own in
  // test_friction_leakage.cpp) is left out of this closed form.
  Machine m = reference_machine();
  m.hydraulics = without_dry_friction_and_leakage(m.hydraulics);
  m.hydraulics.bulk_modulus = 1.2e9;
  const HydraulicParameters& h = m.hydraulics;
  ActuatorParameters p;
  p.fidelity = "hydraulic";
  ActuatorModel a(m, p);
  a.reset(kMid, Vec4(0, 3e5, 1e5, 5e4));
  const Vec4 pa0 = a.pressure_a(), pb0 = a.pressure_b();
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  a.set_command(c);  // closed
  const Vec4 v(0.0, -0.01, 0.005, -0.002);  // m/s: the boom retracts, compressing its bore side
  const double dt = 1e-3;
  for (int k = 0; k < 20; ++k) a.advance(dt, kMid, v);
  for (int i = 1; i < 4; ++i) {
    CAPTURE(i);
    const double Aa = a.area_a()[i], Ab = a.area_b()[i];
    const double stroke = m.q_max()[i] - m.q_min()[i];
    const double Va = h.dead_volume + Aa * (kMid[i] - m.q_min()[i]);
    const double Vb = h.dead_volume + Ab * (m.q_max()[i] - kMid[i]);
    (void)stroke;
    CHECK(a.pressure_a()[i] == doctest::Approx(pa0[i] - 1.2e9 * Aa * v[i] * 0.02 / Va).epsilon(1e-9).scale(0));
    CHECK(a.pressure_b()[i] == doctest::Approx(pb0[i] + 1.2e9 * Ab * v[i] * 0.02 / Vb).epsilon(1e-9).scale(0));
  }
  // The effort is the pressure difference times the areas.
  CHECK(a.effort(kMid)[1] == doctest::Approx(a.area_a()[1] * a.pressure_a()[1] - a.area_b()[1] * a.pressure_b()[1]).scale(0));
}

TEST_CASE("plant/hydraulic spool follows its first-order lag") {
  Machine m = reference_machine();
  m.hydraulics.valve_time_constant = 0.03;
  ActuatorParameters p;
  p.fidelity = "hydraulic";
  ActuatorModel a(m, p);
  a.reset(kMid, Vec4::Zero());
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  c.value = Vec4(0.5, -1, 0.25, 1);
  a.set_command(c);
  for (int k = 0; k < 30; ++k) a.advance(1e-3, kMid, Vec4::Zero());
  CHECK((a.spool() - c.value * (1 - std::exp(-1.0))).norm() < 1e-12);
}

TEST_CASE("plant/hydraulic a stuck spool stays where it stuck while its healthy twin follows the command through the valve's lag from there") {
  // The truth a stuck spool's onset of disagreement is judged on (harness/spool_disagreement.hpp).
  Machine m = reference_machine();
  m.hydraulics.valve_time_constant = 0.03;
  ActuatorParameters p;
  p.fidelity = "hydraulic";
  ActuatorModel a(m, p);
  a.reset(kMid, Vec4::Zero());
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  c.value = Vec4(0, 0.6, 0, 0);
  a.set_command(c);
  for (int k = 0; k < 200; ++k) a.advance(1e-3, kMid, Vec4::Zero());
  const double s0 = a.spool()[1];
  REQUIRE(s0 == doctest::Approx(0.6).epsilon(1e-3));
  CHECK(a.healthy_spool() == a.spool());  // nothing stuck: the same spools
  a.stick_spool(1, s0);
  c.value = Vec4(0, -0.4, 0, 0);
  a.set_command(c);
  for (int k = 0; k < 45; ++k) a.advance(1e-3, kMid, Vec4::Zero());
  CHECK(a.spool()[1] == s0);
  // The healthy one from s0 toward -0.4: -0.4 + (s0 + 0.4) exp(-t / tau), t = 45 ms.
  CHECK(a.healthy_spool()[1] == doctest::Approx(-0.4 + (s0 + 0.4) * std::exp(-0.045 / 0.03)).epsilon(1e-12));
  a.release_spool();
  CHECK(a.healthy_spool() == a.spool());
}

TEST_CASE("plant/orifice flow is continuous at the laminar limit") {
  double f1, d1, f2, d2;
  orifice_flow(0.2e6 * (1 - 1e-9), 0.2e6, f1, d1);
  orifice_flow(0.2e6 * (1 + 1e-9), 0.2e6, f2, d2);
  CHECK(f1 == doctest::Approx(f2).epsilon(1e-6).scale(0));
  CHECK(f2 == doctest::Approx(std::sqrt(0.2e6)).epsilon(1e-6).scale(0));
  orifice_flow(-4e6, 0.2e6, f1, d1);
  CHECK(f1 == doctest::Approx(-2000.0).scale(0));
}

TEST_CASE("plant/hydraulic plant holds its load with closed valves and extends the boom when opened") {
  test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  Plant p(t.scene());
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  const Vec4 q0 = p.state().q_a;
  for (int k = 0; k < 1000; ++k) REQUIRE(p.step(c).ok());
  // The oil springs sag under the load by millimetres, no more.
  CHECK((p.state().q_a - q0).cwiseAbs().maxCoeff() < 0.01);
  c.value = Vec4(0, 1, 0, 0);
  const double l0 = p.state().q_a[1];
  for (int k = 0; k < 1000; ++k) REQUIRE(p.step(c).ok());
  const double speed = (p.state().q_a[1] - l0) / 1.0;
  MESSAGE("boom extension speed with the valve open: " << speed << " m/s (limit 0.32)");
  CHECK(speed > 0.05);
  CHECK(speed < 1.5 * 0.32);
  // A force command is refused by hydraulic actuators, with the reason.
  ActuatorCommand force;
  const PlantStatus st = p.step(force);
  CHECK(st.failure == PlantFailure::bad_command);
  CHECK(std::string(st.text()).find("valve") != std::string::npos);
}

namespace {
// The swing's inertia at a pose, from the model's mass matrix (eq. 17).
double swing_inertia(const Plant& p) {
  Workspace ws(p.model());
  REQUIRE(update_closed_chain(p.model(), ws, p.state().q_a, Vec4::Zero()).ok());
  Mat4 M;
  mass_matrix(p.model(), ws, M);
  return M(0, 0);
}
}  // namespace

TEST_CASE("plant/limited actuator with lag 0 acts in the cycle it is sent: the same run as ideal, bit for bit") {
  test::SceneText t;
  Plant ideal(t.scene());
  t.actuators = "fidelity: limited, lag: 0";
  Plant limited(t.scene());
  ActuatorCommand c;
  for (int k = 0; k < 300; ++k) {
    c.value = ideal.hold_effort();
    c.value[0] = 2e4;                           // a swing torque step from the first cycle
    c.value[1] += 3e4 * std::sin(0.05 * k);     // and a boom force that changes every cycle
    REQUIRE(ideal.step(c).ok());
    REQUIRE(limited.step(c).ok());
    CAPTURE(k);
    REQUIRE(limited.state().q_a == ideal.state().q_a);
    REQUIRE(limited.state().qd_a == ideal.state().qd_a);
    REQUIRE(limited.state().effort == c.value);
  }
  // One cycle in, the swing already turns at h T / I (a 1 ms delay would leave it at rest).
  Plant fresh(t.scene());
  const double inertia = swing_inertia(fresh);
  c.value = fresh.hold_effort();
  c.value[0] = 2e4;
  REQUIRE(fresh.step(c).ok());
  CHECK(fresh.state().qd_a[0] == doctest::Approx(1e-3 * 2e4 / inertia).epsilon(1e-6).scale(0));
}

TEST_CASE("plant/limited actuator with lag tau: the swing's speed is the impulse of exactly T (1 - exp(-t / tau))") {
  // The swing feels no gravity and (in the plane of the front) no coupling to the cylinders, so its
  // speed is the impulse of the applied torque over its inertia: with a first-order lag and no extra
  // delay, qd(t) = T / I (t - tau (1 - exp(-t / tau))). One cycle of delay would give
  // T / I ((t - h) - tau (1 - exp(-(t - h) / tau))), 10 % less at t = 20 ms.
  const double tau = 0.05, T = 2e4, h = 1e-3;
  test::SceneText t;
  t.actuators = "fidelity: limited, lag: 0.05";
  Plant p(t.scene());
  const double inertia = swing_inertia(p);
  ActuatorCommand c;
  c.value = p.hold_effort();
  c.value[0] = T;
  for (int k = 1; k <= 200; ++k) {
    REQUIRE(p.step(c).ok());
    const double time = k * h;
    const double expected = T / inertia * (time - tau * (1.0 - std::exp(-time / tau)));
    CAPTURE(k);
    CHECK(p.state().qd_a[0] == doctest::Approx(expected).epsilon(1e-6).scale(0));
  }
  // The effort reported is the one that acted over the last step: the lag's mean over that step.
  const double t1 = 0.2, t0 = t1 - h;
  const double mean = T * (1.0 - tau / h * (std::exp(-t0 / tau) - std::exp(-t1 / tau)));
  CHECK(p.state().effort[0] == doctest::Approx(mean).epsilon(1e-9).scale(0));
}
