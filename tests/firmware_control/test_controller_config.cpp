#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include "control/controller_config.hpp"
#include "model/machine.hpp"
#include "settings_error_check.hpp"
#include "model/machine_reader.hpp"
#include "control/controller_config_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

// A bad controller section's error: scene.yaml, the field, the place where `at` begins, the reason.
void check_error(const std::string& yaml, const std::string& field, const std::string& at, const std::string& reason) {
  CAPTURE(yaml);
  try {
    read_controller_config(settings::Document::parse(yaml, "scene.yaml"), reference_machine());
    FAIL("no error");
  } catch (const SettingsError& e) {
    exc::test::check_settings_error(e, "scene.yaml", yaml, field, at, reason);
  }
}

}  // namespace

TEST_CASE("firmware/controller config: a scene without controller gets the embedded defaults") {
  const ControllerConfig c = read_controller_config(settings::Document::parse("name: x", "scene.yaml"), reference_machine());
  const ControllerConfig d;
  CHECK(c.law == "adaptive");
  CHECK(c.pid.gains.kp == d.pid.gains.kp);
  CHECK(c.soil_parameters.theta_min == d.soil_parameters.theta_min);
}

TEST_CASE("firmware/controller config: the tracking-error limit defaults by command interface, 5x the valve machine's reach on valves, and a given one is kept through an interface switch") {
  auto read = [](const std::string& yaml) {
    return read_controller_config(settings::Document::parse(yaml, "scene.yaml"), reference_machine());
  };
  const ControllerConfig effort = read("name: x");
  const ControllerConfig valve = read("controller: {command_interface: valve}");
  const ControllerConfig given = read("controller: {command_interface: valve, tracking_error_limit: [0.3, 0.4, 0.5, 0.6]}");
  // The effort interface (the paper's force actuators): the fixed limits.
  CHECK(effort.supervisor.tracking_error_limit == (Vec4() << 0.1, 0.2, 0.2, 0.2).finished());
  // Valves: 5 x swing 7.8 mrad, boom 7.4 mm, arm 19.1 mm, bucket 10.4 mm (the generalisation sweeps).
  CHECK(valve.supervisor.tracking_error_limit[0] == doctest::Approx(0.039));
  CHECK(valve.supervisor.tracking_error_limit[1] == doctest::Approx(0.037));
  CHECK(valve.supervisor.tracking_error_limit[2] == doctest::Approx(0.0955));
  CHECK(valve.supervisor.tracking_error_limit[3] == doctest::Approx(0.052));
  CHECK(given.supervisor.tracking_error_limit == (Vec4() << 0.3, 0.4, 0.5, 0.6).finished());
  // A bench variant switching the interface carries a derived limit with it, a given one not.
  ControllerConfig switched = effort, kept = given;
  set_command_interface(switched, CommandInterface::valve, reference_machine());
  set_command_interface(kept, CommandInterface::effort, reference_machine());
  CHECK(switched.supervisor.tracking_error_limit == valve.supervisor.tracking_error_limit);
  CHECK(kept.supervisor.tracking_error_limit == given.supervisor.tracking_error_limit);
}

TEST_CASE("firmware/controller config parses every field") {
  const ControllerConfig c = read_controller_config(settings::Document::parse(R"(
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
)", "scene.yaml"), reference_machine());
  CHECK(c.law == "slotine_li");
  CHECK(c.period == 0.002);
  CHECK(c.filter.period == 0.002);
  CHECK(c.pid.gains.kp[3] == 400);
  CHECK(c.pid.gains.ki[1] == 10);
  CHECK(c.pid.lyapunov_q[7] == 8);
  CHECK(c.soil_parameters.theta_initial[2] == 50000);
  CHECK(c.adaptation.regressor_acceleration == RegressorAcceleration::desired);
  CHECK(c.slotine_li.kd[0] == 9);
  CHECK(c.filter.acceleration_cutoff_hz == 10);
  CHECK(c.watchdog_timeout == 0.05);
  CHECK(c.actuation.actuator_lag == 0.03);
  CHECK(c.actuation.actuator_lag_target == 0.006);
  CHECK(c.adaptation.integral_action);
  CHECK(c.adaptation.lyapunov_q_integral[3] == 4);
}

TEST_CASE("firmware/controller config errors name the field, its line and column and the allowed range") {
  check_error("controller: {type: lqr}", "controller.type", "lqr", "is 'lqr'; allowed values: pid, adaptive, slotine_li, flow");
  check_error("controller: {kp: [1, 2, 3]}", "controller.kp", "[1, 2, 3]", "must be a list of 4 numbers in [0.001, 1000000] 1/s^2");
  check_error("controller: {kp: [1, 2, -3, 4]}", "controller.kp[2]", "-3", "is -3 1/s^2; allowed range [0.001, 1000000] 1/s^2");
  check_error("controller: {gain: 3}", "controller.gain", "gain", "unknown key; allowed keys: type, period, kp, kv, ki");
  check_error("controller: {theta_initial: [600, 2000, 30000, 100, 2000, 30000]}", "controller.theta_initial[0]", "600",
              "600 outside the bounds 50 .. 500");
  check_error("controller: {theta_min: [50, 1000, 10000, 50, 1000, 2000000]}", "controller.theta_min[5]", "2000000",
              "2000000 must be below theta_max[5] = 1000000");
  check_error("controller: {kp: [100, 100, 100, 100], kv: [10, 10, 10, 10], ki: [2000, 0, 0, 0]}", "controller.ki[0]",
              "2000", "2000 makes the PID loop unstable: must be below kv*kp = 1000");
  check_error("controller: {filters: {velocity_cutoff_hz: 800}}", "controller.filters.velocity_cutoff_hz", "800",
              "800 Hz must be below 500 Hz (Nyquist)");
  check_error("controller: {actuator_lag: 0.02, actuator_lag_target: 0.03}", "controller.actuator_lag_target", "0.03",
              "0.03 s must lie in actuator_lag / 20 .. actuator_lag = 0.001 .. 0.02 s");
  check_error("controller: {actuator_lag: 0.1, actuator_lag_target: 0.001}", "controller.actuator_lag_target", "0.001",
              "0.001 s must lie in actuator_lag / 20 .. actuator_lag = 0.005 .. 0.1 s");
  check_error("controller: {actuator_lag: -0.01}", "controller.actuator_lag", "-0.01", "is -0.01 s; allowed range [0, 1] s");
  check_error("controller: {integral_action: maybe}", "controller.integral_action", "maybe", "is 'maybe'; allowed values: true, false");
  check_error("controller: {lyapunov_q_integral: [1, 0, 1, 1]}", "controller.lyapunov_q_integral[1]", "0, 1, 1]",
              "is 0; allowed range [1e-09, 1e+09]");
  check_error("controller: {period: nan}", "controller.period", "nan", "'nan' is not a number; allowed range [0.00001, 0.1] s");
  check_error("controller: {regressor_acceleration: measured}", "controller.regressor_acceleration", "measured",
              "is 'measured'; allowed values: filtered, desired");
  check_error("controller: [1, 2]", "controller", "[1, 2]", "must be a mapping");
  // Pacing the path to the pumps needs the pumps' commands: the valve interface.
  check_error("controller: {pump_pacing: true}", "controller.pump_pacing", "true",
              "is true; it paces the path to the pumps, which only the valve interface drives");
  check_error("controller: {command_interface: valve, pump_pacing: true, pump_pacing_share: 1.5}", "controller.pump_pacing_share",
              "1.5", "is 1.5; allowed range [0.1, 1]");
}
