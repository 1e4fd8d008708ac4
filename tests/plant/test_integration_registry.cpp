// "One file to add a thing", for integrators: explicit (forward) Euler defined here, in
// this file alone, registered with one call, named by a scene's integrator.method and stepping the
// plant. Checked against its closed form (a step from rest leaves the position where it was and
// gives the velocity h a, where semi-implicit Euler already moves the position by h^2 a) and against
// the shipped RK4 at a fine step: its error halves with the step (first order).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "plant_scenes.hpp"
#include "sim_plant/integration_methods.hpp"

using namespace exc;
using namespace exc::plant;
using exc::plant::test::SceneText;

namespace {

// q and v advance with the step's start velocity and acceleration.
struct ExplicitEuler {
  template <class V>
  static StepOutcome step(const IntegratorSettings&, double h, const V& q0, const V& v0, const Evaluation& start,
                          StepDynamics<V>& dynamics, V& q, V& v) {
    q = q0 + h * v0;
    v = v0 + h * dynamics.acceleration(start);
    return StepOutcome{};
  }
};

void register_explicit_euler_once() {
  static const bool registered = [] {
    register_integration_method(integration_method<ExplicitEuler>("explicit_euler", "forward Euler (a test method)"));
    return true;
  }();
  (void)registered;
}

Vec4 q_after(const Scene& scene, double seconds) {
  Plant plant(scene);
  ActuatorCommand hold;
  hold.value = Vec4::Zero();
  const long cycles = std::lround(seconds / scene.cycle);
  for (long i = 0; i < cycles; ++i) REQUIRE(plant.step(hold).ok());
  return plant.state().q_a;
}

}  // namespace

TEST_CASE("plant/registry: an integration method registered in one call is named by a scene's integrator.method and steps the plant as its closed form says") {
  register_explicit_euler_once();
  // From rest under gravity, zero efforts: the machine starts to fall.
  SceneText t;
  t.method = "explicit_euler";
  t.checks = "energy_tolerance: 1e9";
  const Scene euler_scene = t.scene();
  REQUIRE(euler_scene.integrator.method == "explicit_euler");
  t.method = "semi_implicit_euler";
  const Scene symplectic_scene = t.scene();
  Plant euler(euler_scene), symplectic(symplectic_scene);
  const Vec4 q0 = euler.state().q_a;
  ActuatorCommand none;
  none.value = Vec4::Zero();
  REQUIRE(euler.step(none).ok());
  REQUIRE(symplectic.step(none).ok());
  const double h = euler_scene.integrator.step;
  const Vec4 v1 = symplectic.state().qd_a;  // h a(q0, 0) for both methods
  REQUIRE(v1.norm() > 1e-4);                // gravity moved it
  CHECK((euler.state().qd_a - v1).norm() < 1e-12 * v1.norm() + 1e-15);
  CHECK((euler.state().q_a - q0).lpNorm<Eigen::Infinity>() < 1e-15);  // q1 = q0 + h v0, v0 = 0
  CHECK((symplectic.state().q_a - (q0 + h * v1)).lpNorm<Eigen::Infinity>() < 1e-12);
}

TEST_CASE("plant/registry: the registered forward Euler converges at first order to the shipped RK4, and an unknown method is refused naming it among the registered ones") {
  register_explicit_euler_once();
  const double seconds = 0.5;
  const Vec4 reference = q_after(test::free_motion_scene("rk4", "independent", 1e-4), seconds);
  const double coarse = (q_after(test::free_motion_scene("explicit_euler", "independent", 2e-3), seconds) - reference).norm();
  const double fine = (q_after(test::free_motion_scene("explicit_euler", "independent", 1e-3), seconds) - reference).norm();
  REQUIRE(fine > 0);
  const double order = std::log2(coarse / fine);
  MESSAGE("forward Euler against RK4: " << coarse << " at 2 ms, " << fine << " at 1 ms: order " << order);
  CHECK(order > 0.8);
  CHECK(order < 1.2);

  SceneText t;
  t.method = "explicit_eulr";
  CHECK_THROWS_WITH_AS(t.scene(), doctest::Contains("semi_implicit_euler, rk4, implicit_midpoint, explicit_euler"),
                       settings::SettingsError);
  CHECK_THROWS_AS(register_integration_method(integration_method<ExplicitEuler>("rk4", "taken")), std::invalid_argument);
}
