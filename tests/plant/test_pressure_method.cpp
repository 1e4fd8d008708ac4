// How the chamber pressures are integrated (integrator.pressure_method, sim_plant/chamber.hpp): both
// methods against the closed forms of a chamber draining through a laminar orifice, both with the
// circuit's books closed, and the explicit one stopped by the plant's pressure check where its step
// overshoots a make-up valve, with a message naming it and never a NaN.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "plant_scenes.hpp"
#include "sim_plant/chamber.hpp"

using namespace exc;
using namespace exc::plant;

TEST_CASE("plant/chamber: a laminar drain decays by (1 - h lambda)^k forward and (1 + h lambda)^-k backward, lambda = beta K / (V sqrt(p_lam))") {
  // A closed chamber draining to tank through an orifice in its laminar band (Q = K dp / sqrt(p_lam)):
  // dp/dt = -lambda (p - p_tank). The two Euler updates of that linear equation in closed form,
  // forward stable only while h lambda < 2, backward for every step.
  ChamberValves v;
  v.meter_out_gain = 1e-6;
  v.tank = 0.3e6;
  v.laminar = 0.2e6;
  const double beta = 1e9, volume = 0.005, p0 = v.tank + 0.05e6;  // 3 steps at 1.5x stay in the band
  const double lambda = beta * v.meter_out_gain / (volume * std::sqrt(v.laminar));  // 447 1/s
  for (double h_lambda : {0.5, 1.5, 2.5}) {
    CAPTURE(h_lambda);
    const double h = h_lambda / lambda;
    double pf = p0, pb = p0;
    for (int k = 1; k <= 3; ++k) {
      pf = step_chamber_explicit(v, pf, volume, beta, h, 0, 0).pressure;
      pb = step_chamber(v, pb, volume, beta, h, 0, 0).pressure;
      CHECK(pf - v.tank == doctest::Approx((p0 - v.tank) * std::pow(1 - h_lambda, k)).epsilon(1e-9).scale(0));
      CHECK(pb - v.tank == doctest::Approx((p0 - v.tank) * std::pow(1 + h_lambda, -k)).epsilon(1e-9).scale(0));
    }
    // Forward Euler past h lambda = 2 alternates around tank with a growing amplitude.
    if (h_lambda > 2) CHECK(std::abs(pf - v.tank) > std::abs(p0 - v.tank));
  }
  // One flow evaluation, no iteration.
  CHECK(step_chamber_explicit(v, p0, volume, beta, 1e-4, 0, 0).iterations == 0);
}

namespace {

struct ProfileRun {
  PlantStatus status;
  PlantState last;
  std::vector<Vec3> tip;             // every 10 ms
  std::vector<Vec4> p_a, p_b;        // every 10 ms
};

// The four-function profile of the energy test (test_hydraulics.cpp): every function through its
// valve's range (pump saturation, reliefs, end stops, overrunning loads) in the air; 4 s with the
// given substep and pressure method.
ProfileRun four_functions(double step, const char* method) {
  plant::test::SceneText t;
  t.actuators = "fidelity: hydraulic";
  t.terrain = "height: -5";
  t.step = step;
  t.extra_integrator = std::string("pressure_method: ") + method;
  Plant plant(t.scene());
  ProfileRun r;
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  for (int k = 0; k < 4000 && r.status.ok(); ++k) {
    const double s = k * 1e-3;
    c.value = Vec4(0.6 * std::sin(2.0 * s), 0.8 * std::sin(1.3 * s + 0.5), -0.7 * std::sin(1.7 * s),
                   0.9 * std::sin(2.3 * s + 1.0));
    r.status = plant.step(c);
    if (k % 10 == 9) {
      r.tip.push_back(plant.state().tip_world);
      r.p_a.push_back(plant.state().pressure_a);
      r.p_b.push_back(plant.state().pressure_b);
    }
  }
  r.last = plant.state();
  return r;
}

// RMS over the samples of the tip distance (m) and of the eight chambers' pressure difference (Pa).
void rms_apart(const ProfileRun& a, const ProfileRun& b, double& tip, double& pressure) {
  tip = pressure = 0;
  const std::size_t n = std::min(a.tip.size(), b.tip.size());
  for (std::size_t k = 0; k < n; ++k) {
    tip += (a.tip[k] - b.tip[k]).squaredNorm();
    pressure += (a.p_a[k] - b.p_a[k]).squaredNorm() + (a.p_b[k] - b.p_b[k]).squaredNorm();
  }
  tip = std::sqrt(tip / n);
  pressure = std::sqrt(pressure / (8.0 * n));
}

}  // namespace

TEST_CASE("plant/hydraulics: forward Euler pressures run where their step resolves the valves, with closed books, and the pressure check stops them with a message where it does not") {
  // At 0.25 ms both methods run the 4 s profile; against backward Euler at 25 us each is within 2 mm
  // of tip path and 0.05 MPa of chamber pressure (RMS); the circuit's books close to round-off with
  // either.
  const ProfileRun fine_fe = four_functions(0.25e-3, "forward_euler");
  const ProfileRun fine_be = four_functions(0.25e-3, "backward_euler");
  const ProfileRun reference = four_functions(25e-6, "backward_euler");
  REQUIRE_MESSAGE(fine_fe.status.ok(), fine_fe.status.text());
  REQUIRE_MESSAGE(fine_be.status.ok(), fine_be.status.text());
  REQUIRE_MESSAGE(reference.status.ok(), reference.status.text());
  const HydraulicEnergy& e = fine_fe.last.hydraulics.energy;
  CHECK(std::abs(e.stored - e.stored0 - (e.supplied() - e.piston_work)) < 1e-9 * e.pump_work);
  double tip_fe, p_fe, tip_be, p_be;
  rms_apart(fine_fe, reference, tip_fe, p_fe);
  rms_apart(fine_be, reference, tip_be, p_be);
  MESSAGE("0.25 ms against 25 us: forward Euler tip " << tip_fe * 1e3 << " mm, chambers " << p_fe * 1e-6
                                                      << " MPa; backward Euler " << tip_be * 1e3 << " mm, "
                                                      << p_be * 1e-6 << " MPa (RMS)");
  CHECK(tip_fe < 2e-3);
  CHECK(p_fe < 0.05e6);
  CHECK(tip_be < 2e-3);
  CHECK(p_be < 0.05e6);
  CHECK(fine_fe.last.hydraulics.cavitation_substeps == 0);
  // At 1 ms the explicit update takes a chamber from above tank to below the vapour floor in one
  // step (the make-up valve it never saw): the pressure check stops the plant, naming the chamber,
  // the method and what to change; the state stays finite. Backward Euler runs the same input.
  const ProfileRun coarse = four_functions(1e-3, "forward_euler");
  REQUIRE_FALSE(coarse.status.ok());
  const std::string msg = coarse.status.text();
  MESSAGE(msg);
  CHECK(coarse.status.failure == PlantFailure::pressure_range);
  CHECK(msg.find("pressure_method forward_euler at step 0.001 s") != std::string::npos);
  CHECK(msg.find("backward_euler") != std::string::npos);
  CHECK(msg.find("outside [0,") != std::string::npos);
  CHECK(msg.find("pressure is -") != std::string::npos);
  CHECK(coarse.last.q_a.allFinite());
  CHECK((coarse.last.pressure_a.allFinite() && coarse.last.pressure_b.allFinite()));
  CHECK(four_functions(1e-3, "backward_euler").status.ok());
}
