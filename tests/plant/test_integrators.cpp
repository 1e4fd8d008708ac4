// Integrators x formulations: energy conservation in free motion (no gravity, no damping, no soil),
// order of convergence of the energy error, constraint drift of the augmented form with and without
// stabilisation, agreement of the formulations, error against a fine-step reference.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>

#include "plant_scenes.hpp"

using namespace exc;
using namespace exc::plant;
using exc::plant::test::SceneText;

namespace {

struct RunResult {
  bool ok = true;
  double max_energy_error = 0;  // J
  double max_residual = 0;      // m
  double energy = 0;
  Vec2 rho = Vec2::Zero();
  Vec4 q_a = Vec4::Zero();
  std::string message;
};

using test::free_motion_scene;  // conservative: the energy must stay at its initial value

RunResult run(const Scene& scene, double seconds) {
  Plant plant(scene);
  RunResult r;
  ActuatorCommand cmd;
  cmd.value = plant.hold_effort();  // constant efforts: a conservative load (zero without gravity)
  const int cycles = static_cast<int>(std::lround(seconds / scene.cycle));
  for (int i = 0; i < cycles; ++i) {
    const PlantStatus st = plant.step(cmd);
    if (!st.ok()) {
      r.ok = false;
      r.message = st.text();
      break;
    }
    r.max_energy_error = std::max(r.max_energy_error, std::abs(plant.state().energy_error));
    r.max_residual = std::max(r.max_residual, plant.state().constraint_residual);
  }
  r.energy = plant.energy();
  r.rho = plant.state().rho;
  r.q_a = plant.state().q_a;
  return r;
}

}  // namespace

TEST_CASE("plant/free motion keeps its energy with every integrator and formulation") {
  for (const std::string& m : test::methods()) {
    for (const char* f : test::kFormulations) {
      CAPTURE(std::string(m));
      CAPTURE(std::string(f));
      const Scene s = free_motion_scene(m, f, 1e-3);
      Plant p(s);
      const double e0 = p.energy();
      REQUIRE(e0 > 100.0);  // there is motion to conserve
      const RunResult r = run(s, 1.0);
      REQUIRE(r.ok);
      // 1 ms steps over 1 s: a relative energy drift well under 1 %.
      CHECK(r.max_energy_error < 0.01 * e0);
      MESSAGE(std::string(m) << " / " << f << ": E0 = " << e0 << " J, max |energy drift| = " << r.max_energy_error << " J");
    }
  }
}

TEST_CASE("plant/energy error converges at the order of each method (Euler ~1, midpoint ~2, RK4 ~4)") {
  struct Expect {
    const char* method;
    double lo, hi;
    double h;
  };
  // Step pairs chosen so that the error stays well above round-off.
  const Expect expect[] = {{"semi_implicit_euler", 0.7, 1.5, 4e-3}, {"implicit_midpoint", 1.6, 2.6, 8e-3},
                           {"rk4", 3.0, 5.0, 16e-3}};
  for (const Expect& e : expect) {
    CAPTURE(std::string(e.method));
    const RunResult coarse = run(free_motion_scene(e.method, "independent", e.h), 1.0);
    const RunResult fine = run(free_motion_scene(e.method, "independent", e.h / 2), 1.0);
    REQUIRE(coarse.ok);
    REQUIRE(fine.ok);
    REQUIRE(fine.max_energy_error > 0);
    const double order = std::log2(coarse.max_energy_error / fine.max_energy_error);
    MESSAGE(std::string(e.method) << ": energy error " << coarse.max_energy_error << " J at " << e.h << " s, "
                     << fine.max_energy_error << " J at " << e.h / 2 << " s: order " << order);
    CHECK(order > e.lo);
    CHECK(order < e.hi);
  }
}

TEST_CASE("plant/augmented form drifts off the loop closure without stabilisation, not with it") {
  SceneText t;
  t.method = "semi_implicit_euler";
  t.formulation = "augmented_baumgarte";
  t.qd_a = "[0.3, 0.04, -0.06, 0.08]";
  t.checks = "energy_tolerance: 1e9, constraint_tolerance: 1";
  t.step = 2e-3;
  t.cycle = 2e-3;
  t.extra_integrator = "baumgarte_alpha: 0, baumgarte_beta: 0";
  const RunResult none = run(t.scene(), 3.0);
  t.extra_integrator = "baumgarte_alpha: 20, baumgarte_beta: 20";
  const RunResult baumgarte = run(t.scene(), 3.0);
  t.formulation = "augmented_projection";
  t.extra_integrator = "";
  const RunResult projection = run(t.scene(), 3.0);
  t.formulation = "independent";
  const RunResult independent = run(t.scene(), 3.0);
  INFO(none.message);
  REQUIRE(none.ok);
  REQUIRE(baumgarte.ok);
  REQUIRE(projection.ok);
  REQUIRE(independent.ok);
  MESSAGE("max |h(q)| over 3 s: eq. 8 as written " << none.max_residual << " m, Baumgarte " << baumgarte.max_residual
                                                    << " m, projection " << projection.max_residual
                                                    << " m, independent " << independent.max_residual << " m");
  CHECK(none.max_residual > 1e-7);
  CHECK(baumgarte.max_residual < 0.2 * none.max_residual);
  CHECK(projection.max_residual < 1e-9);
  CHECK(independent.max_residual < 1e-9);
}

TEST_CASE("plant/independent and augmented formulations agree on the same motion") {
  // With gravity and the hold efforts, plus an initial velocity: 1 s, RK4 at 1 ms.
  Vec2 rho[3];
  Vec4 q[3];
  for (int k = 0; k < 3; ++k) {
    SceneText t;
    t.method = "rk4";
    t.formulation = test::kFormulations[k];
    t.qd_a = "[0.2, 0.03, -0.05, 0.06]";
    Plant p(t.scene());
    ActuatorCommand cmd;
    cmd.value = p.hold_effort();
    for (int i = 0; i < 1000; ++i) REQUIRE(p.step(cmd).ok());
    rho[k] = p.state().rho;
    q[k] = p.state().q_a;
  }
  // The machine moved (so agreement says something) ...
  SceneText t0;
  CHECK((q[0] - t0.scene().q_a0).norm() > 0.01);
  // ... and every formulation ends at the same place.
  CHECK((rho[1] - rho[0]).norm() < 1e-4);
  CHECK((rho[2] - rho[0]).norm() < 1e-4);
  CHECK((q[1] - q[0]).norm() < 1e-4);
  CHECK((q[2] - q[0]).norm() < 1e-4);
}

TEST_CASE("plant/every integrator at 1 ms is within millimetres of a fine-step reference") {
  auto scene = [](const std::string& m, const std::string& f, double h) {
    SceneText t;
    t.method = m;
    t.formulation = f;
    t.step = h;
    t.qd_a = "[0.2, 0.03, -0.05, 0.06]";
    return t.scene();
  };
  auto final_tip = [](const Scene& s) {
    Plant p(s);
    ActuatorCommand cmd;
    cmd.value = p.hold_effort();
    for (int i = 0; i < 2000; ++i) REQUIRE(p.step(cmd).ok());
    return Vec2(p.state().rho);
  };
  const Vec2 reference = final_tip(scene("rk4", "independent", 1e-4));
  for (const std::string& m : test::methods()) {
    for (const char* f : test::kFormulations) {
      const double err = (final_tip(scene(m, f, 1e-3)) - reference).norm();
      MESSAGE(std::string(m) << " / " << f << " at 1 ms: tip error after 2 s = " << err * 1e3 << " mm");
      CHECK(err < 5e-3);
    }
  }
}
