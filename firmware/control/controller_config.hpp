#pragma once
// The scene's `controller:` section (gains, Lyapunov weights, adaptation rates, soil-parameter
// bounds, filter cut-offs, watchdog) as the cycle takes it. Every field is optional: a scene without
// `controller:` gets the embedded defaults, each written beside its field in its consumer's struct
// (docs/control.md lists them); the reader (controller_config_reader.hpp) declares each field's unit
// and range once and validates them at start-up on the host. Nothing here reads a file, so the firmware's image compiles it. It holds each
// consumer's settings struct whole, declared in the consumer's room (each law, the actuation stage,
// the path's clock, the supervisor), so that each value and its default is written once and no room
// includes this file: it sits at control/'s top.
#include <cstddef>
#include <cstdint>
#include <string>

#include "control/actuation/actuation_stage.hpp"
#include "control/actuation/command_interface.hpp"
#include "control/control_types.hpp"
#include "control/estimation/state_estimator.hpp"
#include "control/laws/adaptive_law_settings.hpp"
#include "control/laws/computed_torque_pid.hpp"
#include "control/laws/flow_position_control.hpp"
#include "control/laws/slotine_li.hpp"
#include "control/laws/soil_parameter_bounds.hpp"
#include "control/task/path_clock.hpp"
#include "model/machine.hpp"
#include "safety/supervisor.hpp"
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
  // s, the loop's period: every consumer below takes it beside its own settings (the laws integrate
  // at it, the stages and monitors count in it).
  double period = 1e-3;
  // The bus's command set: the actuation stage, the monitors and the laws' interface check read it.
  CommandInterface command_interface = CommandInterface::effort;

  // Each consumer's own settings, held whole: the registry and the node hand each its member.
  PidLawSettings pid;                   // gains, lyapunov_q (the adaptive law builds on them)
  AdaptationSettings adaptation;        // the adaptive law's eq. 27 and beyond (adaptive_law_settings.hpp)
  SoilParameterBounds soil_parameters;  // theta_min, theta_max, theta_initial: both adaptive laws'
  SlotineLiSettings slotine_li;         // controller.slotine_li
  FlowLawSettings flow;                 // controller.flow
  ActuationSettings actuation;          // blend, lag lead and the valve stage (controller.valves)
  PathClockSettings path_clock;         // the path's stop ramp and its pacing to the pumps
  safety::SupervisorSettings supervisor;  // timeouts, the tracking limit and the monitors
  EstimatorConfig filter;               // the state estimator's cut-offs (the adaptive law's filters too)
  double watchdog_timeout = 0.02;       // s without a valid sensor frame -> safe_stop

  // Which derived values the scene gave (derive_defaults leaves those alone).
  GivenSettings given;
};
// The settings blob's field list (app/settings_blob.hpp): a field added above that the cycle reads is
// added here too. Left out: law_given and given, which say how the reader came by a value (the host's
// business, before the blob is made).
template <typename Visitor>
void visit_fields(Visitor& v, ControllerConfig& c) {
  v("law", c.law, kMaxLawName);
  v("period", c.period);
  v.choice("command_interface", c.command_interface, kCommandInterfaces);
  v("pid", c.pid);
  v("adaptation", c.adaptation);
  v("soil_parameters", c.soil_parameters);
  v("slotine_li", c.slotine_li);
  v("flow", c.flow);
  v("actuation", c.actuation);
  v("path_clock", c.path_clock);
  v("supervisor", c.supervisor);
  v("filter", c.filter);
  v("watchdog_timeout", c.watchdog_timeout);
}

// The adaptive law's settings: four of the members above, whole (the registry's factory and tests that
// build the law themselves).
inline AdaptiveLawSettings adaptive_law_settings(const ControllerConfig& c) {
  return AdaptiveLawSettings{c.pid, c.adaptation, c.soil_parameters, c.filter};
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
// The default tracking-error limit for a command interface (SupervisorSettings::tracking_error_limit).
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
