#pragma once
// The scene's `controller:` section (gains, Lyapunov weights, adaptation rates, soil-parameter
// bounds, filter cut-offs, watchdog) as the cycle takes it. Every field is optional: a scene without
// `controller:` gets the embedded defaults below (docs/control.md lists them); the reader
// (controller_config_reader.hpp) declares each field's unit and range once and validates them at
// start-up on the host. Nothing here reads a file, so the firmware's image compiles it. The aggregate
// of every consumer's settings: each law, the actuation stage and the path's clock takes its own part
// (consumer_settings.hpp), so this file sits at control/'s top and no room includes it.
#include <cstddef>
#include <cstdint>
#include <string>

#include "control/actuation/command_interface.hpp"
#include "control/actuation/valve_inner_loop.hpp"
#include "control/control_types.hpp"
#include "control/estimation/soil_contact.hpp"
#include "control/estimation/state_estimator.hpp"
#include "control/laws/adaptive_law_settings.hpp"
#include "control/laws/pid.hpp"
#include "model/machine.hpp"
#include "safety/pressure_plausibility.hpp"
#include "safety/spool_monitor.hpp"
#include "safety/velocity_plausibility.hpp"
#include "settings/enum_table.hpp"

namespace exc::control {

// Which of the values that follow the machine, the command interface and other settings the scene
// gave itself; the others derive_defaults fills. The host's business: not in the settings blob.
struct GivenSettings {
  bool force_time_constant = false, spool_lag_target = false, position_gain = false;  // valves.*
  bool velocity_floor = false, frozen_speed = false;                                  // plausibility.*
  bool adaptation_rate = false, tracking_dead_zone = false;
  bool observer_cutoff = false;  // external_force.cutoff_hz
  bool tracking_error_limit = false;
};

// The longest control law's name the settings blob carries.
inline constexpr std::size_t kMaxLawName = 64;

struct ControllerConfig {
  // The control law to run, by its name in the registry (controller_registry.hpp).
  std::string law = "adaptive";
  bool law_given = false;  // the scene set controller.type (it then chooses the controller to run)
  double period = 1e-3;  // s, the control period (update law integrated at it)

  // Computed-torque error dynamics e'' + kv e' + kp e (+ ki int e for the PID baseline).
  // Order: swing (rad), boom, arm, bucket (m).
  PidGains gains = default_gains();

  // Adaptive law (eqs. 21-28): Q of A^T P + P A + Q = 0, diagonal, x = [e; ed] order. Position
  // weights ~kp make B^T P x lean on e (less on the filtered, lagging ed). Per joint the weights
  // offset the inverse-inertia scaling of Phi = M_a^-1 Y: the light bucket would otherwise dominate
  // the update and the heavy arm learn slowly (tuned on the dig scene: docs/control.md).
  Vec8 lyapunov_q = (Vec8() << 64, 64, 640, 6.4, 1, 1, 10, 0.1).finished();
  // Adaptation rates Gamma^-1 = diag(rate); Theta = [M_x B_x K_x M_z B_z K_z]. Scaled so that each
  // column of Y (rhodd ~0.5 m/s^2, rhod ~0.5 m/s, rho - rho_env ~0.1 m) adapts at a similar pace.
  Vec6 adaptation_rate = (Vec6() << 6e7, 6e10, 3e12, 6e7, 6e10, 3e12).finished();
  // Per joint (rad swing, m): eq. 27 leaves a joint whose |e| is below this out of its update (the
  // standard dead-zone modification). Default on valves: the valve stage's hold window, the error the
  // valves cannot resolve; 0 on efforts (eq. 27 as published).
  Vec4 tracking_dead_zone = Vec4::Zero();
  // Physical bounds of the soil parameters (machine.md): M 50..500 kg, B 1e3..3e4 N s/m,
  // K 1e4..1e6 N/m; and the initial estimate.
  Vec6 theta_min = (Vec6() << 50, 1e3, 1e4, 50, 1e3, 1e4).finished();
  Vec6 theta_max = (Vec6() << 500, 3e4, 1e6, 500, 3e4, 1e6).finished();
  Vec6 theta_initial = (Vec6() << 100, 2e3, 3e4, 100, 2e3, 3e4).finished();
  RegressorAcceleration regressor_acceleration = RegressorAcceleration::filtered;
  ExternalForceSettings external_force;
  SoilContactSettings soil_contact;
  // Beyond the paper: integral action in the adaptive law (K_i and integral_limit as the PID's), with
  // Q of the integral states (z = [int e; e; ed] order: these first, then lyapunov_q).
  bool integral_action = false;
  Vec4 lyapunov_q_integral = (Vec4() << 0.64, 0.64, 6.4, 0.064).finished();  // lyapunov_q e weights / 100 (docs/control.md)

  // Slotine-Li: s = ed + lambda e; tau = ... - kd s (kd in 1/s, scaled by M_a: see slotine_li.hpp).
  // Same error bandwidth as the computed-torque laws: kv = lambda + kd, kp = lambda kd.
  Vec4 sl_lambda = Vec4::Constant(8);
  Vec4 sl_kd = Vec4::Constant(8);
  Vec6 sl_adaptation_rate = (Vec6() << 3e3, 3e5, 3e7, 3e3, 3e5, 3e7).finished();

  // Actuator lag the firmware compensates (actuator_lag_compensator.hpp): the time constant of the
  // machine's effort response (0: ideal force actuators, the paper's; no compensation) and the one
  // the compensated actuator should show. lag / target is the lead's high-frequency gain.
  double actuator_lag = 0;            // s
  double actuator_lag_target = 0.005; // s

  // The bus's command set, and for valves the valve stage's settings (force loop, spool lead).
  CommandInterface command_interface = CommandInterface::effort;
  ValveLoopSettings valves;
  // Flow-based position control (flow_position_control.hpp): u = qd_d - flow_kp e, 1/s. 2 rad/s
  // keeps the position loop below a third of the boom's 2-3 Hz oil column (hydraulics.md).
  Vec4 flow_kp = Vec4::Constant(2);

  EstimatorConfig filter;           // velocity / acceleration cut-offs
  double watchdog_timeout = 0.02;   // s without a valid sensor frame -> safe_stop
  // s without a SUPERVISOR frame, once the operator station has sent a keep-alive (Command none),
  // that stops the machine as the station's stop would (FirmwareFault::operator_link_lost): five
  // of excavator-operator keep-alive's 0.1 s frames missed. 0: the link is not monitored.
  double supervisor_timeout = 0.5;
  // Real time: this many wake-ups in a row after their deadline are a fault (docs/safety.md, H7):
  // one late cycle costs a cycle of latency, five in a row is a loop that lost its period.
  int max_missed_deadlines = 5;
  // Commanded against measured velocity per function on the valve interface (docs/safety.md, H1).
  // Its floors default to shares of each function's top speed and effort (controller_defaults).
  safety::PlausibilitySettings plausibility;
  // The chamber pressures' range, steps and stuck-at readings on the valve interface (docs/safety.md,
  // H4); its limits come from the machine file's hydraulics section (pressure_plausibility.hpp).
  safety::PressurePlausibilitySettings pressure_plausibility;
  // The spool monitor (safety/spool_monitor.hpp; docs/safety.md, H1): each measured spool against
  // its command through the valve's lag, valve interface.
  safety::SpoolMonitorSettings spool_monitor;
  // |q_a - q_d| per joint above which the firmware faults to its safe state (hold and track): a
  // machine far from where it was told to go must stop; rad (swing), m (cylinders). On the valve
  // interface the default is kTrackingLimitMultiple x what the valve machine reaches
  // (kValveMachineReach); on the effort interface (the paper's force actuators, whose PID baseline
  // errs up to 0.12 m on the bucket in its dig) about twice that baseline's worst, 0.5-1 m at the tip.
  Vec4 tracking_error_limit = (Vec4() << 0.1, 0.2, 0.2, 0.2).finished();
  double blend_time = 0.2;          // s, bumpless switch fade
  // A stop along the path (an operator's stop, a stop request) slows the path so that each function
  // decelerates at most its top speed per this time (path_stop.hpp): a function at top speed stops
  // in 0.63 s over its path, a slower one sooner. About the ramp an operator's joystick release gives.
  double stop_ramp_time = 0.4;
  // Valve interface: the path's clock slowed while the path asks the pumps for more than
  // pump_pacing_share of their flow (pump_pacing.hpp), the run lengthened by what that costs. Off by
  // default: the path's times are then the task's, and a path the pumps cannot follow lags until the
  // tracking limit stops it.
  bool pump_pacing = false;
  double pump_pacing_share = 0.9;

  // Which derived values the scene gave (derive_defaults leaves those alone).
  GivenSettings given;

  static PidGains default_gains() {
    PidGains g;
    // omega_n = 8 rad/s (1.3 Hz), critically damped: below the oil-column frequencies of a 20 t
    // machine (1.5-6 Hz, machine.md), so the same gains suit a scene with hydraulics.
    g.kp = Vec4::Constant(64);    // 1/s^2
    g.kv = Vec4::Constant(16);    // 1/s
    g.ki = Vec4::Constant(100);   // 1/s^3: kv kp = 1024 > ki, stable (Routh)
    g.integral_limit = Vec4::Constant(0.05);
    return g;
  }
};
// The settings blob's field list (app/settings_blob.hpp): a field added above that the cycle reads is
// added here too. Left out: law_given and given, which say how the reader came by a value (the host's
// business, before the blob is made).
template <typename Visitor>
void visit_fields(Visitor& v, ControllerConfig& c) {
  v("law", c.law, kMaxLawName);
  v("period", c.period);
  v("gains", c.gains);
  v("lyapunov_q", c.lyapunov_q);
  v("adaptation_rate", c.adaptation_rate);
  v("tracking_dead_zone", c.tracking_dead_zone);
  v("theta_min", c.theta_min);
  v("theta_max", c.theta_max);
  v("theta_initial", c.theta_initial);
  v.choice("regressor_acceleration", c.regressor_acceleration, kRegressorAccelerations);
  v("external_force", c.external_force);
  v("soil_contact", c.soil_contact);
  v("integral_action", c.integral_action);
  v("lyapunov_q_integral", c.lyapunov_q_integral);
  v("sl_lambda", c.sl_lambda);
  v("sl_kd", c.sl_kd);
  v("sl_adaptation_rate", c.sl_adaptation_rate);
  v("actuator_lag", c.actuator_lag);
  v("actuator_lag_target", c.actuator_lag_target);
  v.choice("command_interface", c.command_interface, kCommandInterfaces);
  v("valves", c.valves);
  v("flow_kp", c.flow_kp);
  v("filter", c.filter);
  v("watchdog_timeout", c.watchdog_timeout);
  v("supervisor_timeout", c.supervisor_timeout);
  v("max_missed_deadlines", c.max_missed_deadlines);
  v("plausibility", c.plausibility);
  v("pressure_plausibility", c.pressure_plausibility);
  v("spool_monitor", c.spool_monitor);
  v("tracking_error_limit", c.tracking_error_limit);
  v("blend_time", c.blend_time);
  v("stop_ramp_time", c.stop_ramp_time);
  v("pump_pacing", c.pump_pacing);
  v("pump_pacing_share", c.pump_pacing_share);
}

// The flow plausibility floor as a share of each function's top speed (Machine::speed_max): the
// shipped hydraulic scenes' fault-free figures stay inside it (test firmware/plausibility prints the
// margins), and a spool stuck at a share s of its opening is found after about share / s windows.
inline constexpr double kPlausibilityVelocityShare = 0.1;
// Of a function's top speed: driven faster, its position reading must change within
// plausibility.frozen_sets (0.2 s at 2 %: the bucket's 10 um quantum 280 times over).
inline constexpr double kFrozenSpeedShare = 0.02;
// What the valve machine reaches: the worst |q_a - q_d| per joint (swing rad, boom, arm, bucket m)
// of every law on 1300 runs no law was tuned on, sweeps/generalisation.yaml's 1000 varied digs (pid,
// adaptive, flow: boom 7.4 mm, arm 19.1, bucket 10.4, PID each) and generalisation_swing.yaml's 300
// varied free motions (pid, adaptive: swing 7.8 mrad). Figures of the 20 t reference machine: a
// machine of another size, or a slower valve, reaches other figures (rerun the two sweeps, or set
// controller.tracking_error_limit).
inline constexpr double kValveMachineReach[4] = {0.0078, 0.0074, 0.0191, 0.0104};
// The default tracking-error limit on the valve interface, in multiples of that reach: well clear of
// every fault-free run (the worst is a fifth of it by construction), and far closer than the fixed
// 0.1 rad / 0.2 m (10-27x the reach) that let a stuck spool run 1.45 s.
inline constexpr double kTrackingLimitMultiple = 5;
// The default tracking-error limit for a command interface (ControllerConfig::tracking_error_limit).
Vec4 default_tracking_error_limit(CommandInterface interface);
// Through the valves eq. 27's default rates are the force-commanded machine's times this (period / T_f).
double valve_adaptation_scale(const ControllerConfig& c);
// Every default that follows the nominal machine, the command interface or another setting, in this
// one place; a value the scene gave (c.given) is left alone. Idempotent: the reader calls it before
// each derived key is read (so the effective dump shows what it derived to), a bench after it
// switches the interface. The derivations and their reasons: docs/control.md.
void derive_defaults(ControllerConfig& c, const Machine& nominal);
// The configuration a scene without a `controller:` section gets on `nominal`.
ControllerConfig controller_defaults(const Machine& nominal);
// Switches the command interface of a configuration (a bench variant on other actuators), the
// defaults that follow it derived again.
void set_command_interface(ControllerConfig& c, CommandInterface interface, const Machine& nominal);

}  // namespace exc::control
