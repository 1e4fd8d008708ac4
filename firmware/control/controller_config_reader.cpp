// The `controller:` section: every field declared once (unit, range; the default is the
// field's own, in its consumer's settings struct), then the cross-field rules at the offending field's place.
#include "control/controller_config_reader.hpp"

#include <algorithm>

#include "control/controller_registry.hpp"

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
    if (!(c.soil_parameters.theta_min[i] < c.soil_parameters.theta_max[i]))
      r.fail("theta_min", i, format_number(c.soil_parameters.theta_min[i]) + " must be below theta_max" + idx + " = " +
                                 format_number(c.soil_parameters.theta_max[i]));
    if (c.soil_parameters.theta_initial[i] < c.soil_parameters.theta_min[i] || c.soil_parameters.theta_initial[i] > c.soil_parameters.theta_max[i])
      r.fail("theta_initial", i, format_number(c.soil_parameters.theta_initial[i]) + " outside the bounds " + format_number(c.soil_parameters.theta_min[i]) +
                                     " .. " + format_number(c.soil_parameters.theta_max[i]));
  }
  for (std::size_t j = 0; j < kNumActive; ++j) {
    // e''' + kv e'' + kp e' + ki e = 0 is Hurwitz iff kv kp > ki (Routh).
    if (!(c.pid.gains.kv[j] * c.pid.gains.kp[j] > c.pid.gains.ki[j]))
      r.fail("ki", j, format_number(c.pid.gains.ki[j]) + " makes the PID loop unstable: must be below kv*kp = " +
                          format_number(c.pid.gains.kv[j] * c.pid.gains.kp[j]));
  }
  // A target slower than the lag would lag more, not less; a lead gain above 20 amplifies the
  // measurement noise that reaches the command twentyfold.
  if (c.actuation.actuator_lag > 0 && !(c.actuation.actuator_lag_target <= c.actuation.actuator_lag && c.actuation.actuator_lag <= 20 * c.actuation.actuator_lag_target))
    r.fail("actuator_lag_target", format_number(c.actuation.actuator_lag_target) + " s must lie in actuator_lag / 20 .. actuator_lag = " +
                                      format_number(c.actuation.actuator_lag / 20) + " .. " + format_number(c.actuation.actuator_lag) + " s");
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

void read_controller_config(SectionReader& r, ControllerConfig& c, const Machine& nominal) {
  // The derived defaults (derive_defaults) are filled before each derived key is read, from the
  // values read so far, so that the effective dump shows what each derived to.
  derive_defaults(c, nominal);
  r.choice("type", c.law, c.law_given, controller_registry(),
           "the control law to run (absent: the program's choice; excavator-sim runs pid and adaptive)");
  r.number("period", c.period, {1e-5, 0.1}, "s", "control period (the update law integrated at it)");
  r.numbers("kp", c.pid.gains.kp, {1e-3, 1e6}, "1/s^2", "position gains, swing, boom, arm, bucket");
  r.numbers("kv", c.pid.gains.kv, {1e-3, 1e4}, "1/s", "velocity gains");
  r.numbers("ki", c.pid.gains.ki, {0, 1e8}, "1/s^3", "integral gains (PID baseline; adaptive with integral_action)");
  r.numbers("integral_limit", c.pid.gains.integral_limit, {0, 1e3}, "", "anti-windup bound of the error integral (rad s, m s)");
  r.numbers("lyapunov_q", c.pid.lyapunov_q, kWeight, "", "Q of A^T P + P A + Q = 0, [e; ed] order (eqs. 21-25)");
  r.choice("command_interface", c.command_interface, kCommandInterfaces, "what the firmware commands on the bus");
  SectionReader v = r.section("valves", "the valve stage between the law and a hydraulic machine's valves");
  c.given.force_time_constant = v.value_given("force_time_constant");
  c.given.spool_lag_target = v.value_given("spool_lag_target");
  c.given.position_gain = v.value_given("position_gain");
  derive_defaults(c, nominal);
  v.number("force_time_constant", c.actuation.valves.force_time_constant, {1e-3, 1}, "s", "T_f: the force loop's time constant");
  v.number("force_integral_time", c.actuation.valves.force_integral_time, {0, 100}, "s",
           "T_i of the force loop's integral (0: none; docs/control.md)");
  v.number("spool_lag_target", c.actuation.valves.spool_lag_target, {0, 1}, "s",
           "the spool lag the lead aims for (0: no lead); at most the machine's valve_time_constant");
  v.number("opening_band", c.actuation.valves.opening_band, {0, 0.5}, "", "opening below which the dead-zone inverse is linear");
  derive_defaults(c, nominal);  // the position gain follows T_f
  v.numbers("position_gain", c.actuation.valves.position_gain, {0, 1e3}, "1/s",
            "flow feedforward qd_d - position_gain e: the valve stage's own position correction (default: 1 / (5 T_f))");
  v.numbers("hold_window", c.actuation.valves.hold_window, {0, 0.1}, "",
            "holding a pose: |e| (rad swing, m) inside which a function's valve stays centred");
  v.number("hold_filter_time", c.actuation.valves.hold_filter_time, {0, 10}, "s",
           "holding a pose: the low-pass on the error the in-position judgement reads (0: none; docs/control.md)");
  v.finish();
  SectionReader pl = r.section("plausibility", "commanded against measured velocity per function, valve interface (docs/safety.md)");
  c.given.velocity_floor = pl.value_given("velocity_floor");
  c.given.frozen_speed = pl.value_given("frozen_speed");
  pl.flag("enabled", c.supervisor.plausibility.enabled, "the monitor runs (a fault, emergency stop, when a function moves unlike its command)");
  pl.numbers("velocity_floor", c.supervisor.plausibility.velocity_floor, {1e-4, 10}, "",
             "rad/s (swing), m/s: how much more flow per piston area than commanded may arrive, averaged over the window (default: kPlausibilityVelocityShare of its top speed)");
  pl.number("velocity_fraction", c.supervisor.plausibility.velocity_fraction, {0, 10}, "", "the command's own allowance, of the commanded displacement");
  pl.number("window", c.supervisor.plausibility.window, {1e-3, 10}, "s", "high-pass time constant of the delivered and commanded displacements");
  pl.number("lag", c.supervisor.plausibility.lag, {0, 1}, "s", "first-order lag the commands are expected through");
  pl.number("debounce", c.supervisor.plausibility.debounce, {1e-3, 1}, "s", "how long the residual must stay outside the band");
  pl.whole("frozen_sets", c.supervisor.plausibility.frozen_sets, 2, 1000000, "",
           "sensor sets in a row a position reading may stay bit-identical while its function is driven and the oil shows neither as motion nor as compression");
  pl.numbers("frozen_speed", c.supervisor.plausibility.frozen_speed, {1e-5, 10}, "",
             "rad/s (swing), m/s: the commanded speed above which a reading must change (default: kFrozenSpeedShare of its top speed)");
  pl.finish();
  SectionReader pp = r.section("pressure_plausibility",
                               "the chamber pressures' range, steps and stuck-at readings, valve interface (docs/safety.md, H4)");
  pp.flag("enabled", c.supervisor.pressure_plausibility.enabled, "the monitor runs (a fault, controlled stop, when a chamber pressure is implausible)");
  pp.number("range_margin", c.supervisor.pressure_plausibility.range_margin, {0, 10e6}, "Pa",
            "beyond the circuit's floor and its relief plus override (hydraulics section) a reading is out of range");
  pp.number("step_factor", c.supervisor.pressure_plausibility.step_factor, {1, 100}, "",
            "times the fastest change the oil allows (bulk modulus, chamber volume, port flow): a larger step is a jump");
  pp.whole("frozen_sets", c.supervisor.pressure_plausibility.frozen_sets, 2, 1000000, "",
           "sensor sets in a row with a bit-identical reading while the function moves: a stuck sensor");
  pp.number("moving_share", c.supervisor.pressure_plausibility.moving_share, {1e-3, 1}, "", "of the function's top speed: faster counts as moving");
  pp.whole("debounce", c.supervisor.pressure_plausibility.debounce, 1, 1000, "", "sensor sets in a row the range or the step test must fail");
  pp.finish();
  SectionReader sm = r.section("spool_monitor",
                               "each measured main-valve spool against its command through the valve's lag, valve interface (docs/safety.md, H1)");
  sm.flag("enabled", c.supervisor.spool_monitor.enabled, "the monitor runs (a fault, emergency stop, when a spool disagrees)");
  sm.number("excess", c.supervisor.spool_monitor.excess, {0.01, 2}, "",
            "of the stroke: a spool further from neutral than expected by more than this disagrees");
  sm.number("band", c.supervisor.spool_monitor.band, {0.005, 1}, "",
            "of the stroke: a spool this far on the wrong side of neutral, or off neutral with neutral expected, disagrees");
  sm.number("neutral_expected", c.supervisor.spool_monitor.neutral_expected, {0, 0.5}, "",
            "of the stroke: an expected spool nearer neutral than this counts as neutral commanded");
  sm.whole("debounce", c.supervisor.spool_monitor.debounce, 1, 1000, "", "sensor sets in a row a test must fail");
  sm.finish();
  c.given.adaptation_rate = r.value_given("adaptation_rate");
  c.given.tracking_dead_zone = r.value_given("tracking_dead_zone");
  derive_defaults(c, nominal);  // eq. 27's rates and dead zone follow the interface, the period, T_f and the hold window
  r.numbers("tracking_dead_zone", c.adaptation.tracking_dead_zone, {0, 1}, "",
            "rad (swing), m: eq. 27 leaves a joint out while |e| is below it (default on valves: valves.hold_window)");
  r.numbers("adaptation_rate", c.adaptation.rate, kRate, "",
            "Gamma^-1 = diag(rate), Theta = [M_x B_x K_x M_z B_z K_z] (default on valves: x period / T_f)");
  r.numbers("theta_min", c.soil_parameters.theta_min, kTheta, "", "lower bounds of the soil parameters (projection)");
  r.numbers("theta_max", c.soil_parameters.theta_max, kTheta, "", "upper bounds of the soil parameters");
  r.numbers("theta_initial", c.soil_parameters.theta_initial, kTheta, "", "initial soil estimate");
  r.choice("regressor_acceleration", c.adaptation.regressor_acceleration, kRegressorAccelerations,
           "the joint acceleration in the regressor's M_t term");
  SectionReader sl = r.section("slotine_li", "the Slotine-Li law's gains");
  sl.numbers("lambda", c.slotine_li.lambda, {1e-3, 1e4}, "1/s", "s = ed + lambda e");
  sl.numbers("kd", c.slotine_li.kd, {1e-3, 1e4}, "1/s", "damping of s (scaled by M_a)");
  sl.numbers("adaptation_rate", c.slotine_li.adaptation_rate, kRate, "", "Gamma^-1 of the Slotine-Li update");
  sl.finish();
  SectionReader f = r.section("filters", "the state estimator's cut-offs");
  f.number("velocity_cutoff_hz", c.filter.velocity_cutoff_hz, {0.1, 1e4}, "Hz", "velocity filter cut-off");
  f.number("acceleration_cutoff_hz", c.filter.acceleration_cutoff_hz, {0.1, 1e4}, "Hz", "acceleration filter cut-off");
  f.finish();
  SectionReader ef = r.section("external_force", "the external force observer and the composite update (beyond the paper)");
  ef.flag("observer", c.adaptation.external_force.observer, "add the observer's estimate of what the model misses to eq. 12's command");
  c.given.observer_cutoff = ef.value_given("cutoff_hz");
  derive_defaults(c, nominal);  // the observer's cut-off follows the acceleration filter's
  ef.number("cutoff_hz", c.adaptation.external_force.cutoff_hz, {0.01, 1e3}, "Hz",
            "the observer's low-pass (default: a third of filters.acceleration_cutoff_hz)");
  ef.number("identification_memory", c.adaptation.external_force.identification_memory, {0, 1e6}, "s",
            "the composite update's memory: least squares on the residual of the applied efforts (0: eq. 27 alone)");
  ef.number("force_scale", c.adaptation.external_force.force_scale, {1, 1e8}, "N", "the residual's noise (least squares' measurement noise)");
  ef.number("dead_zone", c.adaptation.external_force.dead_zone, {0, 1e8}, "N", "per cylinder: residuals below it leave the estimates alone");
  ef.finish();
  SectionReader sc = r.section("soil_contact", "how the law tells contact and the soil anchor");
  sc.flag("use_site_map", c.adaptation.soil_contact.use_site_map, "contact and depth from the scene's ground when the firmware has it");
  sc.number("contact_force", c.adaptation.soil_contact.contact_force, {1, 1e8}, "N",
            "without a map: the estimated tip force that tells contact (left below half of it)");
  sc.finish();
  r.number("watchdog_timeout", c.watchdog_timeout, {1e-4, 10}, "s", "without a valid sensor frame -> safe stop");
  r.number("supervisor_timeout", c.supervisor.supervisor_timeout, {0, 60}, "s",
           "without a SUPERVISOR frame once a keep-alive was heard -> the operator's stop (0: not monitored)");
  r.whole("max_missed_deadlines", c.supervisor.max_missed_deadlines, 1, 100000, "",
          "real time: wake-ups in a row after their deadline that are a fault (controlled stop)");
  c.given.tracking_error_limit = r.value_given("tracking_error_limit");
  derive_defaults(c, nominal);
  r.numbers("tracking_error_limit", c.supervisor.tracking_error_limit, {1e-4, 10}, "",
            "rad (swing), m: above it the firmware faults (default on valves: 5x what the machine reaches)");
  r.number("blend_time", c.actuation.blend_time, {0, 10}, "s", "bumpless switch fade");
  r.number("stop_ramp_time", c.path_clock.stop_ramp_time, {0, 10}, "s",
           "a stop along the path decelerates each function by at most its top speed per this time (0: at once)");
  r.flag("pump_pacing", c.path_clock.pump_pacing,
         "valve interface: slow the path's clock while the path asks the pumps for more than pump_pacing_share of their flow");
  r.number("pump_pacing_share", c.path_clock.pump_pacing_share, {0.1, 1}, "",
           "the share of the pumps' flow a paced path may ask (the rest is left to the feedback)");
  if (c.path_clock.pump_pacing && c.command_interface != CommandInterface::valve)
    r.fail("pump_pacing", "is true; it paces the path to the pumps, which only the valve interface drives "
                          "(controller.command_interface: valve)");
  r.flag("integral_action", c.adaptation.integral_action, "integral action in the adaptive law (beyond the paper)");
  r.numbers("lyapunov_q_integral", c.adaptation.lyapunov_q_integral, kWeight, "", "Q of the integral states");
  r.number("actuator_lag", c.actuation.actuator_lag, {0, 1}, "s", "the effort lag the firmware compensates (0: none)");
  r.number("actuator_lag_target", c.actuation.actuator_lag_target, {1e-4, 1}, "s", "the lag the compensated actuator should show");
  SectionReader fl = r.section("flow", "flow-based position control (controller.type flow)");
  fl.numbers("kp", c.flow.kp, {0, 1e3}, "1/s", "position gains: u = qd_d - kp e");
  fl.finish();
  r.finish();
  if (c.law_given) {
    if (const std::string why = interface_misfit(controller_registry().at(c.law), c.command_interface); !why.empty())
      r.fail("type", why);
  }
  derive_defaults(c, nominal);  // the filters' period
  check_nyquist(f, c);
  if (!(c.adaptation.external_force.cutoff_hz < c.filter.acceleration_cutoff_hz))
    ef.fail("cutoff_hz", format_number(c.adaptation.external_force.cutoff_hz) + " Hz must be below filters.acceleration_cutoff_hz = " +
                             format_number(c.filter.acceleration_cutoff_hz) + " Hz (the residual carries that filter's acceleration)");
  check_cross_fields(r, c);
}

ControllerConfig read_controller_config(const settings::Document& scene, const Machine& nominal) {
  SectionReader top(scene);
  SectionReader controller = top.section("controller", "the control law's settings");
  ControllerConfig c;
  read_controller_config(controller, c, nominal);
  return c;
}

}  // namespace exc::control
