#include "app/firmware_node.hpp"

#include <algorithm>
#include <utility>
#include <cmath>
#include <limits>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "app/can_stats_message.hpp"
#include "app/timing_message.hpp"
#include "control/controller_registry.hpp"
#include "exlcm/command_t.hpp"
#include "exlcm/controller_state_t.hpp"
#include "exlcm/fault_t.hpp"
#include "exlcm/timing_t.hpp"
#include "hal/can_protocol.hpp"
#include "hal/clock.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::app {
namespace {

constexpr int kHeartbeatPeriod = hal::kHeartbeatPeriodCycles;
// Sensor sets in a row that say the plant holds while the firmware commands motion before that is a
// fault: the plant applies a command one cycle after it is sent, so a hold it reports on entering
// hold/track lasts one or two sets; five is a machine that does not obey.
constexpr int kPlantHoldCycles = 5;

Vec4 to_vec(const std::array<double, 4>& a) { return Vec4(a[0], a[1], a[2], a[3]); }

bool finite(const Vec4& v) { return v.allFinite(); }

// SensorState::supervisor_pending's bit of a command.
std::uint8_t supervisor_bit(hal::SupervisorCommand c) { return static_cast<std::uint8_t>(1u << static_cast<unsigned>(c)); }

// Refuses a law the command interface cannot carry (a flow law on the effort interface) before it
// is built: std::invalid_argument naming both.
std::unique_ptr<control::Controller> checked_controller(const Model& model, const control::ControllerConfig& config) {
  const control::ControllerEntry& law = control::controller_registry().at(config.law);
  if (const std::string why = control::interface_misfit(law, config.command_interface); !why.empty())
    throw std::invalid_argument("controller " + why + " (the scene's controller.command_interface is " +
                                control::kCommandInterfaces.name_of(config.command_interface) + ")");
  return law.make(model, config);
}

}  // namespace

const char* to_string(FirmwareFault fault) {
  switch (fault) {
    case FirmwareFault::none: return "none";
    case FirmwareFault::sensor_timeout: return "sensor timeout";
    case FirmwareFault::model: return "model";
    case FirmwareFault::tracking_error: return "tracking error";
    case FirmwareFault::no_pressures: return "no pressures";
    case FirmwareFault::pump_limited: return "pumps short of flow";
    case FirmwareFault::plant_emergency: return "plant emergency";
    case FirmwareFault::plant_fault: return "plant fault";
    case FirmwareFault::plant_holding: return "plant holding";
    case FirmwareFault::deadline_overrun: return "missed deadlines";
    case FirmwareFault::velocity_implausible: return "velocity implausible";
    case FirmwareFault::exited: return "firmware exited";
    case FirmwareFault::fatal_error: return "firmware fatal error";
    case FirmwareFault::operator_stop: return "operator stop";
    case FirmwareFault::operator_link_lost: return "operator link lost";
    case FirmwareFault::pressure_implausible: return "pressure implausible";
  }
  return "unknown";
}

const char* to_string(StopKind stop) {
  switch (stop) {
    case StopKind::none: return "none";
    case StopKind::controlled: return "controlled";
    case StopKind::emergency: return "emergency";
  }
  return "unknown";
}

FirmwareNode::FirmwareNode(const Model& model, const control::Task& task, const FirmwareNodeConfig& config,
                           hal::FirmwareCanPort& port, telemetry::TelemetryPublisher* telemetry)
    : model_(model),
      friction_(actuator_friction(model.machine)),
      task_(task),
      config_(config),
      port_(port),
      telemetry_(telemetry),
      controller_(checked_controller(model, config.controller)),
      controller_id_(control::controller_registry().id_of(config.controller.law)),
      estimator_(config.controller.filter),
      machine_(config.controller.watchdog_timeout),
      blender_(config.controller.blend_time),
      lag_compensator_(config.controller.actuator_lag, config.controller.actuator_lag_target,
                       config.controller.period, control::effort_limits_of(model.machine)),
      valves_(control::valve_loop_model(model.machine), config.controller.valves, config.controller.period),
      pacing_(model.machine, config.controller.pump_pacing_share, config.controller.period),
      plausibility_(config.controller.plausibility, config.controller.period),
      frozen_position_(config.controller.plausibility),
      pressure_monitor_(model.machine, config.controller.pressure_plausibility, config.controller.period),
      control_timing_("control", 100.0),
      cycle_timing_("cycle", config.controller.period * 1e6),
      read_timing_("read", 100.0),
      write_timing_("write", 100.0),
      telemetry_timing_("telemetry", 100.0),
      interval_timing_("interval", config.controller.period * 1.5e6),
      period_(config.controller.period) {}

FirmwareNode::~FirmwareNode() = default;

void FirmwareNode::begin_cycle() {
  ++cycle_;
  complete_ = false;
  port_.send_sync(cycle_);
  if (cycle_ % kHeartbeatPeriod == 0) port_.send_heartbeat(static_cast<std::uint8_t>(machine_.mode()));
  // FW_EMERGENCY is IfActive in the DBC: sent on entry to the safe state (end_cycle) and repeated
  // every 10 ms while it lasts, so a node that missed the first frame still learns of the stop.
  if (machine_.mode() == control::Mode::safe_stop && cycle_ > safe_stop_cycle_ &&
      (cycle_ - safe_stop_cycle_) % hal::kEmergencyRepeatCycles == 0)
    send_stop_frame();
}

void FirmwareNode::check_standstill(bool complete) {
  if (machine_.mode() != control::Mode::safe_stop) return;  // tracking: check_plausibility runs the monitor
  if (escalated_ || stop_of(fault_code_) != StopKind::controlled || !complete) {
    plausibility_.update(false);
    cylinder_creep_.restart();
    swing_creep_.restart();
    return;
  }
  const FlowMeasurement m = flow_measurement();
  char why[120] = "";
  if (valve_interface() && sensors_.pressure_valid) {
    // The valves are centred: every bit of oil that arrives is unasked for.
    plausibility_.update(true, Vec4::Zero(), m.position, m.compression, m.at_relief);
    const std::uint8_t found = plausibility_.implausible();
    for (int j = 0; j < 4 && why[0] == 0; ++j)
      if ((found >> j) & 1)
        std::snprintf(why, sizeof why, "%s took %.4f %s with its valve centred", kActiveNames[static_cast<std::size_t>(j)],
                      plausibility_.delivered()[j], j == 0 ? "rad" : "m");
  } else {
    plausibility_.update(false);
  }
  const double since = static_cast<double>(cycle_ - safe_stop_cycle_) * period_;
  if (why[0] == 0 && since >= kStandstillDelay) {
    constexpr double kOut = std::numeric_limits<double>::infinity();
    // The cylinders on the oil they took: motion plus, with pressures, compression (a load that
    // changes, as a braking swing's pull on the front, moves a held cylinder as much as it
    // compresses its oil; no oil arrives). Not the swing: its motor's cross-port leakage moves a
    // swing trapped on its oil spring for seconds.
    const std::uint8_t cylinders =
        cylinder_creep_.update(m.position + m.compression, cycle_, period_, kStandstillWindow,
                               Vec4(kOut, kStandstillCylinderRate, kStandstillCylinderRate, kStandstillCylinderRate), kStandstillSlowing,
                               kStandstillFastFactor);
    // The swing on its motion alone, over windows as long as its oil spring's period, which its
    // ringing averages out of: a spool stuck just past its dead zone creeps on, not slowing.
    const std::uint8_t swing = swing_creep_.update(m.position, cycle_, period_, kStandstillSwingWindow,
                                                   Vec4(kStandstillSwingRate, kOut, kOut, kOut), kStandstillSlowing,
                                                   kStandstillFastFactor);
    for (int j = 1; j < 4 && why[0] == 0; ++j)
      if ((cylinders >> j) & 1)
        std::snprintf(why, sizeof why, "%s takes %.4f m/s on average over %.1f s, not stopping", kActiveNames[static_cast<std::size_t>(j)],
                      cylinder_creep_.mean()[j], cylinder_creep_.window());
    if (why[0] == 0 && (swing & 1))
      std::snprintf(why, sizeof why, "swing moves %.4f rad/s on average over %.1f s, not stopping", swing_creep_.mean()[0],
                    swing_creep_.window());
  }
  if (why[0] == 0) return;
  escalated_ = true;
  send_stop_frame();
  char text[sizeof(exlcm::fault_t::text)];
  std::snprintf(text, sizeof text, "controlled stop escalated to the emergency stop %.2f s after it: %s (%s)", since, why, fault_text_);
  publish_fault(fault_code_, 2, true, text);
}

void FirmwareNode::send_stop_frame() {
  const bool emergency = escalated_ || stop_of(fault_code_) == StopKind::emergency;
  emergency_sent_ = emergency_sent_ || emergency;
  port_.send_fault(emergency, static_cast<std::uint16_t>(fault_code_));
}

void FirmwareNode::send_safe_command(FirmwareFault why) {
  command_.mode = hal::CommandMode::valve;
  command_.value = {0, 0, 0, 0};
  command_.cycle = cycle_;
  command_.firmware_mode = static_cast<std::uint8_t>(control::Mode::safe_stop);
  port_.write(command_);
  // A standing safe state keeps its own fault (and its stop); otherwise the reason of leaving.
  const FirmwareFault code = machine_.mode() == control::Mode::safe_stop ? fault_code_ : why;
  const bool emergency = (machine_.mode() == control::Mode::safe_stop && escalated_) ||
                         stop_of(code) == StopKind::emergency || stop_of(why) == StopKind::emergency;
  emergency_sent_ = emergency_sent_ || emergency;
  port_.send_fault(emergency, static_cast<std::uint16_t>(code));
  safe_command_sent_ = true;
}

void FirmwareNode::check_plant_signals(bool complete) {
  // PLANT_EMERGENCY is an event the plant repeats every 10 ms while it lasts: taken once per frame.
  if (sensors_.plant_emergency) {
    sensors_.plant_emergency = false;
    if (!fault_) {
      raise(FirmwareFault::plant_emergency);
      std::snprintf(pending_text_, sizeof pending_text_,
                    "plant emergency: PLANT_EMERGENCY code %u, plant heartbeat state %u, at t = %.3f s",
                    static_cast<unsigned>(sensors_.plant_fault_code), static_cast<unsigned>(sensors_.plant_heartbeat_state),
                    time());
    }
  }
  if (!complete) return;
  if (sensors_.plant_faults != 0 && !fault_) {
    raise(FirmwareFault::plant_fault);
    std::snprintf(pending_text_, sizeof pending_text_, "plant fault: SENS_MACHINE PlantFaults 0x%02x at t = %.3f s",
                  static_cast<unsigned>(sensors_.plant_faults), time());
  }
  const bool commanding = machine_.mode() == control::Mode::hold || machine_.mode() == control::Mode::track;
  plant_hold_run_ = commanding && (sensors_.plant_state & hal::kPlantStateHolding) != 0 ? plant_hold_run_ + 1 : 0;
  if (plant_hold_run_ >= kPlantHoldCycles && !fault_) {
    raise(FirmwareFault::plant_holding);
    std::snprintf(pending_text_, sizeof pending_text_,
                  "plant holding: PlantState %u for %d sensor sets while commanded (heartbeat state %u) at t = %.3f s",
                  static_cast<unsigned>(sensors_.plant_state), plant_hold_run_,
                  static_cast<unsigned>(sensors_.plant_heartbeat_state), time());
  }
}

void FirmwareNode::take_supervisor_commands() {
  const std::uint8_t pending = sensors_.supervisor_pending;
  sensors_.supervisor_pending = 0;
  if ((pending & supervisor_bit(hal::SupervisorCommand::start)) != 0) start_received_ = true;
  // The operator link: armed by the station's first keep-alive, lost after supervisor_timeout
  // without any frame (ISO 15817's remote control: losing the link stops the machine). Taken as the
  // station's stop; heard again, a later loss is a new one.
  if ((pending & supervisor_bit(hal::SupervisorCommand::none)) != 0) link_armed_ = true;
  if (pending != 0) {
    last_supervisor_time_ = time();
    link_lost_ = false;
  }
  const double timeout = config_.controller.supervisor_timeout;
  const bool lost_now = link_armed_ && !link_lost_ && timeout > 0 && time() - last_supervisor_time_ > timeout;
  if (lost_now) {
    link_lost_ = true;
    link_stop_ = true;
  }
  const bool stop_frame = (pending & supervisor_bit(hal::SupervisorCommand::stop)) != 0;
  if (stop_frame) link_stop_ = false;  // the station's own stop
  const bool stop_now = stop_frame || lost_now;
  if (stop_now) {
    operator_stop_pending_ = true;
    start_received_ = false;  // a stop withdraws a start: the next begin needs a new one
  }
  const control::Mode mode = machine_.mode();
  if (mode == control::Mode::safe_stop && !stop_now) {
    operator_stop_pending_ = false;  // stopped already: the stop has latched
  } else if (operator_stop_pending_ && (mode == control::Mode::hold || mode == control::Mode::track) && !fault_) {
    // Not yet commanding (start-up): taken on the first cycle the node commands the machine. A
    // tracking machine first decelerates along its path; the stop latches once the path is at rest.
    operator_stop_pending_ = false;
    if (!operator_stop_on_rest_) operator_stop_time_ = time();
    operator_stop_on_rest_ = true;
    if (mode == control::Mode::track && !path_stop_.active()) begin_path_stop(time());
  }
  if (operator_stop_on_rest_ && !path_stop_moving(time()) && !fault_) {
    operator_stop_on_rest_ = false;
    raise(link_stop_ ? FirmwareFault::operator_link_lost : FirmwareFault::operator_stop);
    pending_time_ = operator_stop_time_;  // detected when its frame came (or failed to), whatever the deceleration took
    if (link_stop_) {
      link_stop_ = false;
      std::snprintf(pending_text_, sizeof pending_text_,
                    "operator link lost: no SUPERVISOR frame for %.3f s (the last at t = %.3f s), in %s; the path at rest "
                    "%.3f s later",
                    config_.controller.supervisor_timeout, last_supervisor_time_, control::to_string(mode),
                    time() - operator_stop_time_);
    } else {
      std::snprintf(pending_text_, sizeof pending_text_,
                    "operator stop: SUPERVISOR stop in %s at t = %.3f s, the path at rest %.3f s later",
                    control::to_string(mode), operator_stop_time_, time() - operator_stop_time_);
    }
  }
}

bool FirmwareNode::path_stop_moving(double t) const {
  return path_stop_.active() && !path_stop_.done(t - path_stop_start_);
}

void FirmwareNode::begin_path_stop(double t) {
  const bool paced = config_.controller.pump_pacing;
  const double tau0 = paced ? pacing_.tau() : unslowed_task_time(t);
  Vec4 q, yd, ydd;
  task_.trajectory.evaluate(tau0, q, yd, ydd);
  path_stop_.begin(tau0, yd, model_.machine.speed_max(), config_.controller.stop_ramp_time, paced ? pacing_.rate() : 1.0);
  path_stop_start_ = t;
}

double FirmwareNode::path_time_at(double t, double& rate, double& rate_dot) const {
  if (!path_stop_.active()) {
    // Paced, the clock is a state stepped once a cycle (compute_command), read here at this cycle's t.
    const bool paced = config_.controller.pump_pacing;
    rate = paced ? pacing_.rate() : 1;
    rate_dot = paced ? pacing_.rate_dot() : 0;
    return paced ? pacing_.tau() : unslowed_task_time(t);
  }
  double tau = 0;
  path_stop_.path_time(t - path_stop_start_, tau, rate, rate_dot);
  return tau;
}

bool FirmwareNode::receive() {
  if (port_.read(sensors_) && sensors_.motion_valid && sensors_.cycle == cycle_) complete_ = true;
  return complete_;
}

void FirmwareNode::end_cycle() {
  const std::int64_t start_ns = hal::monotonic_now_ns();
  const double t = time();
  const bool complete = receive();
  if (complete) {
    have_valid_ = true;
    last_valid_time_ = t;
  }
  // An acknowledge is spent on this cycle: it clears the latched faults of the safe state, and the
  // monitors that watch standing conditions (the plant's signals below, the watchdog) raise again
  // if theirs still stands. A stop in the same cycle is raised after it, so it stands.
  const std::uint8_t supervisor = sensors_.supervisor_pending;
  if ((supervisor & supervisor_bit(hal::SupervisorCommand::acknowledge)) != 0) acknowledge_requested_ = true;
  const bool acknowledged = acknowledge_requested_ && machine_.mode() == control::Mode::safe_stop &&
                            (supervisor & supervisor_bit(hal::SupervisorCommand::stop)) == 0;
  acknowledge_requested_ = false;
  if (acknowledged) {
    fault_ = false;
    pending_fault_ = FirmwareFault::none;
  }
  take_supervisor_commands();
  check_plant_signals(complete);
  const std::int64_t read_ns = hal::monotonic_now_ns();
  read_timing_.record_ns(read_ns - start_ns);

  // A stop request decelerates a tracking machine along its path first; it holds once the path is at rest.
  if (stop_requested_ && machine_.mode() == control::Mode::track && !path_stop_.active()) begin_path_stop(t);
  // The path time before the transition, for the end-of-task test; compute_command takes it again
  // after it (a transition into track restarts the path's clock).
  const double tau = path_time_at(t);

  control::StateMachineInputs in;
  in.t = t;
  in.have_valid_frame = have_valid_;
  in.last_valid_frame_time = last_valid_time_;
  // The task starts once. After a safe stop the machine holds where it is when the sensors are back:
  // resuming would restart the path from its first point, a step command nobody asked for.
  in.track_requested = t >= config_.track_delay && safe_stops_ == 0 && (start_received_ || !config_.wait_for_start);
  in.stop_requested = stop_requested_ && !path_stop_moving(t);
  // Once the task has ended it stays ended: hold must not re-enter track and restart the path.
  in.trajectory_finished = finished_ || (machine_.mode() == control::Mode::track && tau >= task_.end_time());
  in.fault = fault_;
  in.acknowledged = acknowledged;
  const control::Transition transition = machine_.step(in);
  transition_ = transition;
  if (transition.changed) {
    if (transition.from == control::Mode::track) path_stop_.cancel();
    if (transition.to == control::Mode::hold) {
      // From track, hold where the path was (its last point when it ended): the desired pose never
      // steps. From start-up or a safe stop, hold where the machine is.
      held_q_ = transition.from == control::Mode::track ? q_d_ : to_vec(sensors_.position);
      if (transition.from == control::Mode::track && !finished_ && in.trajectory_finished) {
        Vec4 qd_end, qdd_end;
        task_.trajectory.evaluate(task_.end_time(), held_q_, qd_end, qdd_end);
        finished_ = true;
        finish_time_ = t;
      }
      fault_ = false;
      pending_fault_ = FirmwareFault::none;
      // Leaving an acknowledged stop: the machine's emergency latch is released (EmergencyStop = 0,
      // no fault) so it obeys the commands again.
      if (transition.from == control::Mode::safe_stop) port_.send_fault(false, 0);
      escalated_ = false;
    }
    if (transition.to == control::Mode::track) {
      track_start_ = t;
      pacing_.start(task_.start_time());
    }
    if (transition.to == control::Mode::safe_stop) {
      operator_stop_on_rest_ = false;  // whatever stopped the machine, an operator's stop under way is in it
      ++safe_stops_;
      safe_stop_cycle_ = cycle_;
      fault_code_ = fault_ ? pending_fault_ : FirmwareFault::sensor_timeout;
      // A sensor timeout is detected from the first cycle of the gap that ended in it.
      fault_detected_time_ = fault_ ? pending_time_ : last_valid_time_ + period_;
      if (fault_code_ == FirmwareFault::sensor_timeout)
        std::snprintf(fault_text_, sizeof fault_text_, "sensor timeout: no valid sensor set for %.0f ms at t = %.3f s",
                      (t - last_valid_time_) * 1e3, t);
      else
        std::memcpy(fault_text_, pending_text_, sizeof fault_text_);
      send_stop_frame();
    }
  }

  check_standstill(complete);
  compute_command(transition);
  const std::int64_t write_start_ns = hal::monotonic_now_ns();
  port_.write(command_);
  const std::int64_t write_end_ns = hal::monotonic_now_ns();
  write_timing_.record_ns(write_end_ns - write_start_ns);
  if (machine_.mode() == control::Mode::track) measured_.add(to_vec(sensors_.position), q_d_);
  if (telemetry_ != nullptr) publish_cycle();
  if (telemetry_ != nullptr && transition.changed) {
    const bool stop = transition.to == control::Mode::safe_stop;
    char text[sizeof(exlcm::fault_t::text)];
    std::snprintf(text, sizeof text, "%s -> %s: %s%s%s", control::to_string(transition.from),
                  control::to_string(transition.to), transition.reason, stop ? ": " : "", stop ? fault_text_ : "");
    publish_fault(stop ? fault_code_ : FirmwareFault::none, stop ? 2 : 0, stop, text);
  }
  // The cycle's scope (stated once, in firmware_node.hpp): read to telemetry encoded, the periodic
  // counter messages included.
  if (telemetry_ != nullptr && cycle_ % kCounterPeriod == 0) publish_counters();
  const std::int64_t end_ns = hal::monotonic_now_ns();
  if (telemetry_ != nullptr) telemetry_timing_.record_ns(end_ns - write_end_ns);
  cycle_timing_.record_ns(end_ns - start_ns);
}

void FirmwareNode::scan_state(SubnormalScan& scan) const {
  // What came in and went out.
  scan.scan("firmware sensors.position", sensors_.position);
  scan.scan("firmware sensors.velocity", sensors_.velocity);
  scan.scan("firmware sensors.pressure_a", sensors_.pressure_a);
  scan.scan("firmware sensors.pressure_b", sensors_.pressure_b);
  scan.scan("firmware sensors.pump_pressure", sensors_.pump_pressure);
  scan.scan("firmware command.value", command_.value);
  scan.scan("firmware command.pilot_a", command_.pilot_a);
  scan.scan("firmware command.pilot_b", command_.pilot_b);
  // The estimator's filters: their memory is these outputs and the inputs above, one cycle back.
  scan.scan("estimator position", estimator_.position());
  scan.scan("estimator velocity (Butterworth)", estimator_.velocity());
  scan.scan("estimator acceleration (filtered derivative)", estimator_.acceleration());
  // The path and the hold.
  scan.scan("q_desired", q_d_);
  scan.scan("qd_desired", qd_d_);
  scan.scan("qdd_desired", qdd_d_);
  scan.scan("held q", held_q_);
  scan.scan("last effort sent", last_sent_);
  // The law.
  scan.scan("law tau", out_.tau);
  scan.scan("law tau_unsaturated", out_.tau_unsaturated);
  scan.scan("law e", out_.e);
  scan.scan("law ed", out_.ed);
  scan.scan("law theta_hat", out_.theta_hat);
  scan.scan("law lyapunov", out_.lyapunov);
  scan.scan("law lyapunov_tracking", out_.lyapunov_tracking);
  scan.scan("law rho", out_.rho);
  scan.scan("law rho_env", out_.rho_env);
  scan.scan("law velocity (flow law)", out_.velocity);
  scan.scan("law disturbance (observer)", out_.disturbance);
  scan.scan("law tip_force", out_.tip_force);
  struct LawScan final : control::StateVisitor {
    explicit LawScan(SubnormalScan& s) : scan(s) {}
    void visit(const char* name, const double* values, std::size_t count) override { scan.scan(name, values, count); }
    SubnormalScan& scan;
  } law_scan(scan);
  controller_->visit_state(law_scan);
  // The stages after the law: the actuator-lag lead and the valve stage.
  scan.scan("actuator-lag lead delivered effort", lag_compensator_.delivered());
  const control::ValveCommand& v = valves_.last();
  scan.scan("valve stage velocity", v.velocity);
  scan.scan("valve stage opening", v.opening);
  scan.scan("valve stage spool command", v.spool);
  scan.scan("valve stage pilot_a", v.pilot_a);
  scan.scan("valve stage pilot_b", v.pilot_b);
  scan.scan("valve stage measured force", v.force);
  scan.scan("valve stage demanded flow", v.demanded_flow);
  scan.scan("valve stage spool lead model", valves_.spool_model());
  scan.scan("valve stage force integral", valves_.force_integral());
}

void FirmwareNode::publish_fault(FirmwareFault code, std::int8_t severity, bool active, const char* text) {
  if (telemetry_ == nullptr) return;
  exlcm::fault_t f{};
  f.utime = utime();
  f.code = static_cast<std::int32_t>(code);
  f.severity = severity;
  f.active = active;
  std::snprintf(reinterpret_cast<char*>(f.text), sizeof(f.text), "%s", text);
  telemetry_->publish(telemetry::Channel::fault, f);
}

void FirmwareNode::update_pump_warning(bool limited, double demanded_flow) {
  if (pump_warning_) pump_warning_peak_ = std::max(pump_warning_peak_, demanded_flow);
  pump_run_ = limited != pump_warning_ ? pump_run_ + 1 : 0;
  if (pump_run_ < kPumpWarningCycles) return;
  pump_run_ = 0;
  pump_warning_ = limited;
  const double pumps = model_.machine.hydraulics.pump_flow, t = time();
  if (limited) {
    ++pump_warnings_;
    pump_warning_start_ = t;
    pump_warning_peak_ = demanded_flow;
    std::snprintf(warning_text_, sizeof warning_text_,
                  "pumps short of flow: the valves ask %.0f L/min of their %.0f L/min, every function slows to %.0f %% "
                  "(t = %.3f s)",
                  demanded_flow * 60000, pumps * 60000, 100 * pumps / demanded_flow, t);
  } else {
    std::snprintf(warning_text_, sizeof warning_text_,
                  "pumps within their flow again after %.2f s (at most %.0f L/min asked of %.0f; t = %.3f s)",
                  t - pump_warning_start_, pump_warning_peak_ * 60000, pumps * 60000, t);
  }
  publish_fault(FirmwareFault::pump_limited, 1, limited, warning_text_);
}

void FirmwareNode::record_wakeup(std::int64_t interval_ns, std::uint64_t overruns, std::uint64_t skipped) {
  interval_timing_.record_ns(interval_ns);
  const bool missed = overruns > deadline_overruns_ || skipped > skipped_deadlines_;
  missed_in_a_row_ = missed ? missed_in_a_row_ + 1 : 0;
  deadline_overruns_ = overruns;
  skipped_deadlines_ = skipped;
  const bool commanding = machine_.mode() == control::Mode::hold || machine_.mode() == control::Mode::track;
  if (missed_in_a_row_ >= config_.controller.max_missed_deadlines && commanding && !fault_) {
    raise(FirmwareFault::deadline_overrun);
    pending_time_ = time() + period_;  // the cycle about to start
    std::snprintf(pending_text_, sizeof pending_text_,
                  "missed deadlines: %d wake-ups in a row after their deadline (limit %d) at t = %.3f s", missed_in_a_row_,
                  config_.controller.max_missed_deadlines, pending_time_);
  }
}

void FirmwareNode::compute_command(const control::Transition& transition) {
  const control::Mode mode = machine_.mode();
  command_.cycle = cycle_;
  command_.firmware_mode = static_cast<std::uint8_t>(mode);
  if (mode != control::Mode::hold && mode != control::Mode::track) {
    // No valid sensors (or a fault): the safe state is valves centred, i.e. zero cylinder flow and
    // the swing brake; the plant holds the machine where it is.
    command_.mode = hal::CommandMode::valve;
    command_.value = {0, 0, 0, 0};
    last_sent_.setZero();
    update_pump_warning(false, 0);  // centred valves ask nothing
    pressure_monitor_.update(false, false, Vec4::Zero(), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
    return;
  }
  const std::int64_t start_ns = hal::monotonic_now_ns();
  const double t = time();
  const Vec4 q = to_vec(sensors_.position);
  const Vec4 qd = to_vec(sensors_.velocity);
  // Entering hold/track after a stop or at start: the estimator, the law and the lag model restart.
  const bool restarted = transition.changed && (transition.from == control::Mode::safe_stop ||
                                                transition.from == control::Mode::wait_sensors);
  if (restarted) {
    estimator_.reset(q, qd);
    controller_->reset();
    valves_.reset();
  } else {
    estimator_.update(q, qd);
  }

  if (mode == control::Mode::track) {
    double rate = 1, rate_dot = 0;
    path_time_ = path_time_at(t, rate, rate_dot);
    task_.trajectory.evaluate(path_time_, q_d_, qd_d_, qdd_d_);
    if (path_stop_.active()) {
      const Vec4 yd = qd_d_, ydd = qdd_d_;  // in path time
      control::PathStop::scale(rate, rate_dot, yd, ydd, qd_d_, qdd_d_);
    } else if (config_.controller.pump_pacing) {
      const Vec4 yd = qd_d_, ydd = qdd_d_;
      pacing_.update(yd);
      control::PathStop::scale(pacing_.rate(), pacing_.rate_dot(), yd, ydd, qd_d_, qdd_d_);
      pacing_.advance();
    }
  } else {
    q_d_ = held_q_;
    qd_d_.setZero();
    qdd_d_.setZero();
  }

  control::ControlInput input;
  input.t = t;
  input.q = estimator_.position();
  input.qd = estimator_.velocity();
  input.qd_measured = qd;
  input.qdd = estimator_.acceleration();
  input.q_d = q_d_;
  input.qd_d = qd_d_;
  input.qdd_d = qdd_d_;
  input.soil.site_map = &config_.site_map;
  input.soil.theta_known = config_.theta_known;
  input.soil.theta = config_.theta_true;
  // What the stage after the law could not deliver last cycle (a clamped lead, a fully open valve):
  // the adaptive laws leave those joints out of their update, the PID its integrator.
  input.actuator_limited = valve_interface() ? valves_.last().limited : lag_compensator_.clamped();
  input.applied = restarted ? control::AppliedEffort{} : applied_effort();
  out_ = controller_->update(input);
  if (!fault_ && (out_.status != ModelStatus::ok || !finite(out_.tau))) {
    raise(FirmwareFault::model);
    std::snprintf(pending_text_, sizeof pending_text_, "model: the closed-chain model refused the state at t = %.3f s", t);
  }
  // Far from where it was told to go: stop (the state machine takes the safe state next cycle). In
  // the first cycle of the task the machine is not standing where the task starts: said as such.
  const bool task_start = mode == control::Mode::track && transition.changed;
  for (int j = 0; j < 4 && !fault_; ++j) {
    const double limit = config_.controller.tracking_error_limit[j];
    if (std::abs(out_.e[j]) > limit) {
      raise(FirmwareFault::tracking_error);
      const char* const name = kActiveNames[static_cast<std::size_t>(j)];
      const char* const unit = j == 0 ? "rad" : "m";
      if (task_start)
        std::snprintf(pending_text_, sizeof pending_text_, "tracking error at the task's start: %s %.4f %s from its first point > limit %.4f",
                      name, std::abs(out_.e[j]), unit, limit);
      else if (pump_warning_)  // the likely cause, named: a path that asks more than the pumps give lags
        std::snprintf(pending_text_, sizeof pending_text_,
                      "tracking error: %s %.4f %s > limit %.4f at t = %.3f s, the pumps short of flow since t = %.3f s", name,
                      std::abs(out_.e[j]), unit, limit, t, pump_warning_start_);
      else
        std::snprintf(pending_text_, sizeof pending_text_, "tracking error: %s %.4f %s > limit %.4f at t = %.3f s", name,
                      std::abs(out_.e[j]), unit, limit, t);
    }
  }

  // Bumpless: entering hold/track from another effort-commanding mode starts from the last command.
  if (transition.changed && (transition.from == control::Mode::hold || transition.from == control::Mode::track))
    blender_.on_switch(t, last_sent_, out_.tau);
  if (valve_interface()) {
    check_pressures(restarted);
    command_valves(q);
    check_plausibility(restarted);
  } else {
    const Vec4 tau = blender_.apply(t, out_.tau);
    // After a restart the actuator is taken to deliver what the law asks for first (the plant's
    // actuators hold their effort); last_sent_ stays the effort asked for, the blend's reference.
    if (restarted) lag_compensator_.reset(tau);
    const Vec4 sent = lag_compensator_.apply(tau);
    command_.mode = hal::CommandMode::effort;
    for (int j = 0; j < 4; ++j) command_.value[j] = sent[j];
    last_sent_ = tau;
  }
  control_timing_.record_ns(hal::monotonic_now_ns() - start_ns);
}

Vec4 FirmwareNode::seal_friction(const Vec4& v, const Vec4& p_a, const Vec4& p_b) const {
  return smooth_friction(friction_, v, p_a, p_b);
}

control::AppliedEffort FirmwareNode::applied_effort() const {
  control::AppliedEffort a;
  if (valve_interface()) {
    if (!sensors_.pressure_valid) return a;
    const Vec4 p_a = to_vec(sensors_.pressure_a), p_b = to_vec(sensors_.pressure_b);
    // What the cylinders push minus what their seals take (the nominal machine's friction): the
    // effort the mechanism receives, as the model's M_a qdd + h_a + J_t^T F_soil describes it.
    a.effort = valves_.measured_force(p_a, p_b) - seal_friction(estimator_.velocity(), p_a, p_b);
    a.valid = a.measured = true;
    const control::ValveCommand& v = valves_.last();
    a.suspect = static_cast<std::uint8_t>(v.limited | valves_.off_map(p_a, p_b) | (v.pump_limited ? 0x0F : 0));
    return a;
  }
  if (command_.mode != hal::CommandMode::effort) return a;  // nothing commanded yet, or valves centred
  // The command still holds last cycle's efforts (this cycle's are computed after the law).
  a.effort = lag_compensator_.active() ? lag_compensator_.delivered() : to_vec(command_.value);
  a.valid = true;
  a.suspect = static_cast<std::uint8_t>(lag_compensator_.clamped() | out_.saturated);
  return a;
}

FirmwareNode::FlowMeasurement FirmwareNode::flow_measurement() const {
  FlowMeasurement m;
  m.position = to_vec(sensors_.position);
  // Without pressures (or valves) the compression is unknown: the monitor then sees the motion alone.
  if (!valve_interface() || !sensors_.pressure_valid) return m;
  const Vec4 p_a = to_vec(sensors_.pressure_a), p_b = to_vec(sensors_.pressure_b);
  m.compression = valves_.measured_force(p_a, p_b).cwiseQuotient(valves_.hydraulic_stiffness(m.position));
  m.at_relief = valves_.at_relief(p_a, p_b);
  return m;
}

void FirmwareNode::check_plausibility(bool restarted) {
  // The command just computed is what the valves are told from now on; the motion and pressures
  // measured now answer the commands before it, which the monitor's lag stands for.
  const control::ValveCommand& v = valves_.last();
  const FlowMeasurement m = flow_measurement();
  const std::uint8_t found = plausibility_.update(!restarted, v.velocity, m.position, m.compression, m.at_relief);
  const std::uint8_t frozen = frozen_position_.update(!restarted, plausibility_, m.position, m.at_relief);
  const std::uint8_t either = found | frozen;
  if (either == 0 || fault_ || !plausibility_.settings().enabled) return;
  int j = 0;
  while (((either >> j) & 1) == 0) ++j;
  raise(FirmwareFault::velocity_implausible);
  const char* const unit = j == 0 ? "rad" : "m";
  const double window = plausibility_.settings().window;
  if (((found >> j) & 1) == 0) {
    std::snprintf(pending_text_, sizeof pending_text_,
                  "no motion at t = %.3f s: %s read %.5f %s for %d sets while asked %.3f %s/s", time(),
                  kActiveNames[static_cast<std::size_t>(j)], m.position[j], unit, frozen_position_.settings().frozen_sets,
                  plausibility_.expected()[j], unit);
    return;
  }
  // (fits pending_text_: the times first, the figures after)
  std::snprintf(pending_text_, sizeof pending_text_,
                "flow implausible at t = %.3f s: %s took %.4f %s over %.2f s, asked %.4f (velocity %.3f, flow asked %.3f)", time(),
                kActiveNames[static_cast<std::size_t>(j)], plausibility_.delivered()[j], unit, window, plausibility_.asked()[j],
                estimator_.velocity()[j], plausibility_.expected()[j]);
  // Detected when the debounce is complete: the time a fault's start is judged against.
}

void FirmwareNode::check_pressures(bool restarted) {
  const Vec4 p_a = to_vec(sensors_.pressure_a), p_b = to_vec(sensors_.pressure_b);
  const std::uint8_t found = pressure_monitor_.update(!restarted && sensors_.pressure_valid, complete_, p_a, p_b,
                                                      to_vec(sensors_.position), to_vec(sensors_.velocity));
  if (found == 0 || fault_) return;
  int c = 0;
  while (((found >> c) & 1) == 0) ++c;
  raise(FirmwareFault::pressure_implausible);
  const int j = c / 2;
  const double p = (c % 2 == 0 ? p_a : p_b)[j];
  std::snprintf(pending_text_, sizeof pending_text_, "pressure implausible at t = %.3f s: %s %s %.2f MPa %s", time(),
                kActiveNames[static_cast<std::size_t>(j)], c % 2 == 0 ? "A" : "B", p * 1e-6,
                control::to_string(pressure_monitor_.test_of(c)));
}

void FirmwareNode::raise(FirmwareFault fault) {
  fault_ = true;
  pending_fault_ = fault;
  pending_time_ = time();
}

void FirmwareNode::command_valves(const Vec4& q) {
  const Vec4 p_a = to_vec(sensors_.pressure_a), p_b = to_vec(sensors_.pressure_b);
  valves_.set_holding(machine_.mode() == control::Mode::hold, out_.e);
  const control::ValveCommand* v = nullptr;
  if (out_.velocity_command) {
    v = &valves_.from_velocity(out_.velocity, q, p_a, p_b);
  } else {
    // The force loop closes on the measured chamber pressures: without them it would drive the
    // valves blind. Fault (the safe state centres the valves next cycle) rather than guess.
    if (!sensors_.pressure_valid && !fault_) {
      raise(FirmwareFault::no_pressures);
      std::snprintf(pending_text_, sizeof pending_text_,
                    "no pressures: the valve stage's force loop needs the chamber pressures (t = %.3f s)", time());
    }
    const Vec4 tau = blender_.apply(time(), out_.tau);
    last_sent_ = tau;
    const Vec4 v_ff = qd_d_ - valves_.settings().position_gain.cwiseProduct(out_.e);
    // The cylinders push what the mechanism needs plus what their seals take (the nominal machine's
    // friction, signed by the velocity the valves are asked for, which does not chatter with the
    // sensors' noise; applied_effort() takes it back out of the measured force).
    v = &valves_.from_force(tau + seal_friction(v_ff, p_a, p_b), v_ff, q, p_a, p_b);
  }
  if (v->pump_limited) ++pump_limited_cycles_;
  update_pump_warning(v->pump_limited, v->demanded_flow);
  command_.mode = hal::CommandMode::pilot;
  for (int j = 0; j < 4; ++j) {
    command_.value[j] = v->spool[j];
    command_.pilot_a[j] = v->pilot_a[j];
    command_.pilot_b[j] = v->pilot_b[j];
  }
}

void FirmwareNode::publish_cycle() {
  const std::int64_t utime = this->utime();
  exlcm::command_t c{};
  c.utime = utime;
  c.mode = static_cast<std::int8_t>(machine_.mode());
  c.controller = controller_id_;
  c.command_interface = static_cast<std::int8_t>(config_.controller.command_interface);
  const bool effort = command_.mode == hal::CommandMode::effort;
  const bool valves = command_.mode == hal::CommandMode::pilot;
  const control::ValveCommand& v = valves_.last();
  for (int j = 0; j < 4; ++j) {
    c.effort[j] = effort ? command_.value[j] : valves && !out_.velocity_command ? last_sent_[j] : 0.0;
    c.valve[j] = effort ? 0.0 : command_.value[j];
    c.saturated[j] = ((out_.saturated | (valves ? v.limited : 0)) >> j) & 1;
    c.valve_velocity[j] = valves ? v.velocity[j] : 0.0;
    c.pilot_a[j] = valves ? v.pilot_a[j] : 0.0;
    c.pilot_b[j] = valves ? v.pilot_b[j] : 0.0;
    c.force_measured[j] = valves ? v.force[j] : 0.0;
  }
  c.pump_limited = valves && v.pump_limited;
  telemetry_->publish(telemetry::Channel::command, c);

  exlcm::controller_state_t s{};
  s.utime = utime;
  s.controller = controller_id_;
  s.mode = static_cast<std::int8_t>(machine_.mode());
  for (int j = 0; j < 4; ++j) {
    s.q_desired[j] = q_d_[j];
    s.qd_desired[j] = qd_d_[j];
    s.error[j] = out_.e[j];
    s.error_rate[j] = out_.ed[j];
  }
  for (int i = 0; i < 6; ++i) {
    s.theta_hat[i] = out_.theta_hat[i];
    s.theta_true[i] = config_.theta_known ? config_.theta_true[i] : std::nan("");
  }
  s.lyapunov = out_.lyapunov;
  telemetry_->publish(telemetry::Channel::controller, s);
}

void FirmwareNode::publish_counters(bool after_exit_command) {
  if (telemetry_ == nullptr) return;
  // The exit's safe command goes out after the last cycle: its frames' bus time falls in the period
  // after it, the window EXC_CAN_STATS's load is taken over.
  const double window_end = time() + (after_exit_command ? period_ : 0.0);
  const std::int64_t utime = this->utime() + (after_exit_command ? static_cast<std::int64_t>(std::llround(period_ * 1e6)) : 0);
  // Every stage of the loop (timing_t.stage): 0 the whole end_cycle, 1 read, 2 update (estimate,
  // trajectory, law), 3 write, 6 telemetry encode; 5 the wake-up interval of a real-time loop, whose
  // overruns field carries the deadlines missed (the plant publishes 4, its step).
  exlcm::timing_t m{};
  const std::pair<const control::PerfCounter*, std::int8_t> stages[kTimingStages] = {
      {&cycle_timing_, 0}, {&read_timing_, 1}, {&control_timing_, 2}, {&write_timing_, 3}, {&telemetry_timing_, 6}};
  for (const auto& [counter, stage] : stages) {
    fill_timing(*counter, stage, utime, m);
    telemetry_->publish(telemetry::Channel::timing, m);
  }
  if (interval_timing_.count() > 0) {
    fill_timing(interval_timing_, 5, utime, m);
    m.overruns = static_cast<std::int64_t>(deadline_overruns_);
    m.skipped = static_cast<std::int64_t>(skipped_deadlines_);
    telemetry_->publish(telemetry::Channel::timing, m);
  }

  // The firmware sends or receives every frame of the two-node bus: its counts are the bus's.
  const double load = bus_load_.update(port_.tx_stats().bus_ns + port_.rx_bus_ns(), window_end);
  const exlcm::can_stats_t cs = can_stats_message(port_.rx_stats(), port_.tx_stats(), 0, utime, load);
  telemetry_->publish(telemetry::Channel::can_stats, cs);
}

}  // namespace exc::app
