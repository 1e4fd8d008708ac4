// The `controller:` section: every field declared once (unit, range; the default is the
// ControllerConfig member's), then the cross-field rules at the offending field's place.
#include "control/controller_config.hpp"

#include "control/controller_kinds.hpp"

namespace exc::control {
namespace {

using settings::format_number;
using settings::Need;
using settings::SectionReader;

constexpr settings::Bounds kRate{0, 1e16};
constexpr settings::Bounds kTheta{0, 1e8};
constexpr settings::Bounds kWeight{1e-9, 1e9};

void check_cross_fields(const SectionReader& r, const ControllerConfig& c) {
  for (std::size_t i = 0; i < 6; ++i) {
    const std::string idx = "[" + std::to_string(i) + "]";
    if (!(c.theta_min[i] < c.theta_max[i]))
      r.fail("theta_min", i, format_number(c.theta_min[i]) + " must be below theta_max" + idx + " = " +
                                 format_number(c.theta_max[i]));
    if (c.theta_initial[i] < c.theta_min[i] || c.theta_initial[i] > c.theta_max[i])
      r.fail("theta_initial", i, format_number(c.theta_initial[i]) + " outside the bounds " + format_number(c.theta_min[i]) +
                                     " .. " + format_number(c.theta_max[i]));
  }
  for (std::size_t j = 0; j < kNumActive; ++j) {
    // e''' + kv e'' + kp e' + ki e = 0 is Hurwitz iff kv kp > ki (Routh).
    if (!(c.gains.kv[j] * c.gains.kp[j] > c.gains.ki[j]))
      r.fail("ki", j, format_number(c.gains.ki[j]) + " makes the PID loop unstable: must be below kv*kp = " +
                          format_number(c.gains.kv[j] * c.gains.kp[j]));
  }
  // The leak is integrated by explicit Euler at the control period: below 10 periods it overshoots.
  if (c.adaptation_leakage_time > 0 && c.adaptation_leakage_time < 10 * c.period)
    r.fail("adaptation_leakage_time", format_number(c.adaptation_leakage_time) + " s must be 0 (no leakage) or at least 10 "
                                      "control periods = " + format_number(10 * c.period) + " s");
  // A target slower than the lag would lag more, not less; a lead gain above 20 amplifies the
  // measurement noise that reaches the command twentyfold.
  if (c.actuator_lag > 0 && !(c.actuator_lag_target <= c.actuator_lag && c.actuator_lag <= 20 * c.actuator_lag_target))
    r.fail("actuator_lag_target", format_number(c.actuator_lag_target) + " s must lie in actuator_lag / 20 .. actuator_lag = " +
                                      format_number(c.actuator_lag / 20) + " .. " + format_number(c.actuator_lag) + " s");
}

// The filters must sit below the Nyquist frequency of the control period.
void check_nyquist(const SectionReader& f, const ControllerConfig& c) {
  const double nyquist = 0.5 / c.period;
  if (!(c.filter.velocity_cutoff_hz < nyquist))
    f.fail("velocity_cutoff_hz", format_number(c.filter.velocity_cutoff_hz) + " Hz must be below " + format_number(nyquist) +
                                     " Hz (Nyquist)");
  if (!(c.filter.acceleration_cutoff_hz < nyquist))
    f.fail("acceleration_cutoff_hz", format_number(c.filter.acceleration_cutoff_hz) + " Hz must be below " +
                                         format_number(nyquist) + " Hz (Nyquist)");
}

}  // namespace

const char* to_string(ControllerKind kind) { return kControllerKinds.name_of(kind); }

void read_controller_config(SectionReader& r, ControllerConfig& c) {
  r.choice("type", c.kind, c.kind_given, kControllerKinds,
           "the control law to run (absent: the program's choice; excavator-sim runs pid and adaptive)");
  r.number("period", c.period, {1e-5, 0.1}, "s", "control period (the update law integrated at it)");
  r.numbers("kp", c.gains.kp, {1e-3, 1e6}, "1/s^2", "position gains, swing, boom, arm, bucket");
  r.numbers("kv", c.gains.kv, {1e-3, 1e4}, "1/s", "velocity gains");
  r.numbers("ki", c.gains.ki, {0, 1e8}, "1/s^3", "integral gains (PID baseline; adaptive with integral_action)");
  r.numbers("integral_limit", c.gains.integral_limit, {0, 1e3}, "", "anti-windup bound of the error integral (rad s, m s)");
  r.numbers("lyapunov_q", c.lyapunov_q, kWeight, "", "Q of A^T P + P A + Q = 0, [e; ed] order (eqs. 21-25)");
  r.numbers("adaptation_rate", c.adaptation_rate, kRate, "", "Gamma^-1 = diag(rate), Theta = [M_x B_x K_x M_z B_z K_z]");
  r.numbers("theta_min", c.theta_min, kTheta, "", "lower bounds of the soil parameters (projection)");
  r.numbers("theta_max", c.theta_max, kTheta, "", "upper bounds of the soil parameters");
  r.numbers("theta_initial", c.theta_initial, kTheta, "", "initial soil estimate");
  r.number("adaptation_leakage_time", c.adaptation_leakage_time, {0, 1e6}, "s",
           "leakage of the update toward theta_initial while it runs (beyond the paper; 0: none, eq. 27)");
  r.choice("regressor_acceleration", c.regressor_acceleration, kRegressorAccelerations,
           "the joint acceleration in the regressor's M_t term");
  SectionReader sl = r.section("slotine_li", "the Slotine-Li law's gains");
  sl.numbers("lambda", c.sl_lambda, {1e-3, 1e4}, "1/s", "s = ed + lambda e");
  sl.numbers("kd", c.sl_kd, {1e-3, 1e4}, "1/s", "damping of s (scaled by M_a)");
  sl.numbers("adaptation_rate", c.sl_adaptation_rate, kRate, "", "Gamma^-1 of the Slotine-Li update");
  sl.finish();
  SectionReader f = r.section("filters", "the state estimator's cut-offs");
  f.number("velocity_cutoff_hz", c.filter.velocity_cutoff_hz, {0.1, 1e4}, "Hz", "velocity filter cut-off");
  f.number("acceleration_cutoff_hz", c.filter.acceleration_cutoff_hz, {0.1, 1e4}, "Hz", "acceleration filter cut-off");
  f.finish();
  r.number("watchdog_timeout", c.watchdog_timeout, {1e-4, 10}, "s", "without a valid sensor frame -> safe stop");
  r.numbers("tracking_error_limit", c.tracking_error_limit, {1e-4, 10}, "", "rad (swing), m: above it the firmware faults");
  r.number("blend_time", c.blend_time, {0, 10}, "s", "bumpless switch fade");
  r.flag("integral_action", c.integral_action, "integral action in the adaptive law (beyond the paper)");
  r.numbers("lyapunov_q_integral", c.lyapunov_q_integral, kWeight, "", "Q of the integral states");
  r.number("actuator_lag", c.actuator_lag, {0, 1}, "s", "the effort lag the firmware compensates (0: none)");
  r.number("actuator_lag_target", c.actuator_lag_target, {1e-4, 1}, "s", "the lag the compensated actuator should show");
  r.choice("command_interface", c.command_interface, kCommandInterfaces, "what the firmware commands on the bus");
  SectionReader v = r.section("valves", "the valve stage between the law and a hydraulic machine's valves");
  v.number("force_time_constant", c.valves.force_time_constant, {1e-3, 1}, "s", "T_f: the force loop's time constant");
  v.number("force_integral_time", c.valves.force_integral_time, {0, 100}, "s",
           "T_i of the force loop's integral (0: none; docs/control.md)");
  v.number("spool_lag_target", c.valves.spool_lag_target, {0, 1}, "s",
           "the spool lag the lead aims for (0: no lead); at most the machine's valve_time_constant");
  v.number("opening_band", c.valves.opening_band, {0, 0.5}, "", "opening below which the dead-zone inverse is linear");
  v.numbers("position_gain", c.valves.position_gain, {0, 1e3}, "1/s",
            "flow feedforward qd_d - position_gain e: the valve stage's own position correction");
  v.numbers("hold_window", c.valves.hold_window, {0, 0.1}, "",
            "holding a pose: |e| (rad swing, m) inside which a function's valve stays centred");
  v.finish();
  SectionReader fl = r.section("flow", "flow-based position control (controller.type flow)");
  fl.numbers("kp", c.flow_kp, {0, 1e3}, "1/s", "position gains: u = qd_d - kp e");
  fl.finish();
  r.finish();
  if (c.kind_given && c.kind == ControllerKind::flow && c.command_interface != CommandInterface::valve)
    r.fail("type", "flow commands the valves' flow: it needs command_interface: valve");
  c.filter.period = c.period;
  check_nyquist(f, c);
  check_cross_fields(r, c);
}

ControllerConfig read_controller_config(const settings::Document& scene) {
  SectionReader top(scene);
  SectionReader controller = top.section("controller", "the control law's settings");
  ControllerConfig c;
  read_controller_config(controller, c);
  return c;
}

}  // namespace exc::control
