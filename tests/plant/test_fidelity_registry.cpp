// "One file to add a thing", for actuator fidelities: slow force actuators (the commanded
// efforts through a first-order lag of 50 ms, no clamp, no stops) defined here, in this file alone,
// registered with one call, named by a scene's actuators.fidelity and run on the plant. Checked
// against closed forms: the effort's step response hold + d (1 - exp(-t / T)) at every cycle, and the
// swing's angle under it against the ideal actuators' on the same machine, whose ratio is independent
// of the swing's inertia: (t^2/2 - T t + T^2 (1 - exp(-t / T))) / (t^2 / 2).
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "plant_scenes.hpp"
#include "sim_plant/actuator_fidelity.hpp"

using namespace exc;
using namespace exc::plant;
using exc::plant::test::SceneText;

namespace {

constexpr double kLag = 0.05;  // s

// The effort follows the command with y' = (u - y) / T, advanced exactly over each substep and held
// on the machine from the substep's start (ActuatorDynamics::effort_over's default).
class SlowForceActuators final : public ActuatorDynamics {
 public:
  SlowForceActuators(const Machine&, const ActuatorParameters&, HydraulicCircuit&) {}
  void reset(const Vec4&, const Vec4& hold) override { command_ = effort_ = hold; }
  void set_command(const ActuatorCommand& command) override { command_ = command.value; }
  Vec4 effort(const Vec4&) const override { return effort_; }
  void advance(double dt, const Vec4&, const Vec4&) override { effort_ += -std::expm1(-dt / kLag) * (command_ - effort_); }

 private:
  Vec4 command_ = Vec4::Zero(), effort_ = Vec4::Zero();
};

double slow_force_lag(const ActuatorParameters&) { return kLag; }

void register_slow_force_once() {
  static const bool registered = [] {
    register_actuator_fidelity({"slow_force", "efforts through a 50 ms first-order lag (a test fidelity)",
                                build_actuators<SlowForceActuators>, ActuatorInput::efforts, 0, slow_force_lag});
    return true;
  }();
  (void)registered;
}

Scene scene_with(const std::string& fidelity) {
  SceneText t;
  t.actuators = "fidelity: " + fidelity;
  return t.scene();
}

}  // namespace

TEST_CASE("plant/registry: an actuator fidelity registered in one call is named by a scene's actuators.fidelity, and its effort and the swing's motion follow their closed forms") {
  register_slow_force_once();
  const Scene slow_scene = scene_with("slow_force");
  REQUIRE(slow_scene.actuators.fidelity == "slow_force");
  Plant slow(slow_scene), ideal(scene_with("ideal"));
  REQUIRE(slow.status().ok());
  CHECK(slow.fidelity().effort_lag(slow_scene.actuators) == kLag);
  CHECK_FALSE(slow.fidelity().takes_valves());

  // From rest, held against gravity; a swing torque step of d at t = 0 (the swing carries no gravity).
  const Vec4 hold = slow.hold_effort();
  const double d = 2e4;  // N m
  ActuatorCommand step;
  step.value = hold;
  step.value[0] += d;
  const double h = slow_scene.integrator.step;
  const double q0 = slow.state().q_a[0];
  double worst_effort = 0;
  const int cycles = 200;
  for (int k = 1; k <= cycles; ++k) {
    REQUIRE(slow.step(step).ok());
    REQUIRE(ideal.step(step).ok());
    // The effort reported is the one held over the last substep: the lag's value at its start.
    const double t_held = slow.state().time - h;
    const double expected = hold[0] + d * -std::expm1(-t_held / kLag);
    worst_effort = std::max(worst_effort, std::abs(slow.state().effort[0] - expected));
    // The other functions keep holding their gravity load.
    CHECK((slow.state().effort.tail<3>() - hold.tail<3>()).norm() < 1e-9 * hold.norm());
  }
  MESSAGE("slow_force: worst effort error against hold + d (1 - exp(-t/T)) over " << cycles
                                                                                  << " cycles: " << worst_effort << " N m");
  CHECK(worst_effort < 1e-9 * d);
  REQUIRE(ideal.state().q_a[0] - q0 > 1e-4);  // the swing moved
  const double t = slow.state().time;
  const double ratio = (slow.state().q_a[0] - q0) / (ideal.state().q_a[0] - q0);
  const double closed = (t * t / 2 - kLag * t + kLag * kLag * -std::expm1(-t / kLag)) / (t * t / 2);
  MESSAGE("swing angle after " << t << " s: slow_force / ideal = " << ratio << ", closed form " << closed);
  // Semi-implicit Euler at 1 ms over 200 steps: both angles within about 1/200 of their closed forms.
  CHECK(ratio == doctest::Approx(closed).epsilon(0.01));
}

TEST_CASE("plant/registry: the registered fidelity's entry answers for it: valve commands are refused, an unknown name lists it, a taken name is refused") {
  register_slow_force_once();
  Plant slow(scene_with("slow_force"));
  ActuatorCommand valve;
  valve.mode = ActuatorCommand::valve;
  const PlantStatus s = slow.step(valve);
  REQUIRE_FALSE(s.ok());
  CHECK(s.failure == PlantFailure::bad_command);
  CHECK(std::string(s.text()).find("valve commands for actuators.fidelity slow_force; slow_force actuators take efforts") !=
        std::string::npos);

  CHECK_THROWS_WITH_AS(scene_with("slow_forse"), doctest::Contains("ideal, limited, hydraulic, slow_force"),
                       settings::SettingsError);
  CHECK(actuator_fidelities().help().find("slow_force: efforts through a 50 ms first-order lag") != std::string::npos);
  CHECK_THROWS_AS(register_actuator_fidelity({"ideal", "taken", build_actuators<SlowForceActuators>}), std::invalid_argument);
  CHECK_THROWS_AS(register_actuator_fidelity({"no_factory", "none", nullptr}), std::invalid_argument);
}
