#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include "control/controller_config.hpp"

using namespace exc;
using namespace exc::control;

namespace {

std::string error_of(const std::string& yaml) {
  try {
    parse_controller_config(YAML::Load(yaml)["controller"], "scene.yaml");
  } catch (const ConfigError& e) {
    return e.field() + " | " + e.reason();
  }
  return "no error";
}

}  // namespace

TEST_CASE("firmware/controller config: a scene without controller gets the embedded defaults") {
  const ControllerConfig c = parse_controller_config(YAML::Load("name: x")["controller"], "scene.yaml");
  const ControllerConfig d;
  CHECK(c.kind == ControllerKind::adaptive);
  CHECK(c.gains.kp == d.gains.kp);
  CHECK(c.theta_min == d.theta_min);
  // The defaults themselves are valid.
  CHECK_NOTHROW(validate(d, "<defaults>"));
}

TEST_CASE("firmware/controller config parses every field") {
  const ControllerConfig c = parse_controller_config(YAML::Load(R"(
controller:
  type: slotine_li
  period: 0.002
  kp: [100, 200, 300, 400]
  kv: [20, 30, 40, 50]
  ki: [0, 10, 20, 30]
  integral_limit: [0.1, 0.1, 0.1, 0.1]
  lyapunov_q: [1, 2, 3, 4, 5, 6, 7, 8]
  adaptation_rate: [1, 2, 3, 4, 5, 6]
  theta_min: [60, 2000, 20000, 60, 2000, 20000]
  theta_max: [400, 20000, 900000, 400, 20000, 900000]
  theta_initial: [100, 3000, 50000, 100, 3000, 50000]
  regressor_acceleration: desired
  slotine_li: {lambda: [5, 6, 7, 8], kd: [9, 10, 11, 12], adaptation_rate: [1, 1, 1, 1, 1, 1]}
  filters: {velocity_cutoff_hz: 30, acceleration_cutoff_hz: 10}
  watchdog_timeout: 0.05
  blend_time: 0.1
  actuator_lag: 0.03
  actuator_lag_target: 0.006
  integral_action: true
  lyapunov_q_integral: [1, 2, 3, 4]
)")["controller"], "scene.yaml");
  CHECK(c.kind == ControllerKind::slotine_li);
  CHECK(c.period == 0.002);
  CHECK(c.filter.period == 0.002);
  CHECK(c.gains.kp[3] == 400);
  CHECK(c.gains.ki[1] == 10);
  CHECK(c.lyapunov_q[7] == 8);
  CHECK(c.theta_initial[2] == 50000);
  CHECK(c.regressor_acceleration == RegressorAcceleration::desired);
  CHECK(c.sl_kd[0] == 9);
  CHECK(c.filter.acceleration_cutoff_hz == 10);
  CHECK(c.watchdog_timeout == 0.05);
  CHECK(c.actuator_lag == 0.03);
  CHECK(c.actuator_lag_target == 0.006);
  CHECK(c.integral_action);
  CHECK(c.lyapunov_q_integral[3] == 4);
}

TEST_CASE("firmware/controller config errors name the field and the allowed range") {
  CHECK(error_of("controller: {type: lqr}") == "controller.type | 'lqr' (allowed: pid, adaptive, slotine_li)");
  CHECK(error_of("controller: {kp: [1, 2, 3]}").find("controller.kp | must be a list of 4 numbers") == 0);
  CHECK(error_of("controller: {kp: [1, 2, -3, 4]}").find("controller.kp[2] | -3 outside the allowed range") == 0);
  CHECK(error_of("controller: {gain: 3}").find("controller.gain | unknown key (allowed: ") == 0);
  CHECK(error_of("controller: {theta_initial: [600, 2000, 30000, 100, 2000, 30000]}")
            .find("controller.theta_initial[0] | 600 outside the bounds 50 .. 500") == 0);
  CHECK(error_of("controller: {theta_min: [50, 1000, 10000, 50, 1000, 2000000]}")
            .find("controller.theta_min[5] | 2e+06 must be below theta_max[5]") == 0);
  CHECK(error_of("controller: {kp: [100, 100, 100, 100], kv: [10, 10, 10, 10], ki: [2000, 0, 0, 0]}")
            .find("controller.ki[0] | 2000 makes the PID loop unstable") == 0);
  CHECK(error_of("controller: {filters: {velocity_cutoff_hz: 800}}").find("controller.filters.velocity_cutoff_hz | 800 Hz must be below 500 Hz") == 0);
  CHECK(error_of("controller: {actuator_lag: 0.02, actuator_lag_target: 0.03}")
            .find("controller.actuator_lag_target | 0.03 s must lie in actuator_lag / 20 .. actuator_lag = 0.001 .. 0.02 s") == 0);
  CHECK(error_of("controller: {actuator_lag: 0.1, actuator_lag_target: 0.001}").find("controller.actuator_lag_target | ") == 0);
  CHECK(error_of("controller: {actuator_lag: -0.01}").find("controller.actuator_lag | -0.01 outside the allowed range 0 .. 1") == 0);
  CHECK(error_of("controller: {integral_action: maybe}") == "controller.integral_action | 'maybe' (allowed: true, false)");
  CHECK(error_of("controller: {lyapunov_q_integral: [1, 0, 1, 1]}").find("controller.lyapunov_q_integral[1] | 0 outside the allowed range") == 0);
  CHECK(error_of("controller: {period: nan}").find("controller.period | ") == 0);
}
