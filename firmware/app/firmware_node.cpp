#include "app/firmware_node.hpp"

#include <cstdio>

#include "app/cycle_messages.hpp"
#include "exlcm/fault_t.hpp"
#include "hal/can_protocol.hpp"
#include "hal/clock.hpp"
#include "telemetry/telemetry_sink.hpp"

namespace exc::app {
namespace {

Vec4 to_vec(const std::array<double, 4>& a) { return Vec4(a[0], a[1], a[2], a[3]); }

control::ChamberPressures pressures_of(const hal::SensorState& s) {
  return control::ChamberPressures{s.pressure_valid, to_vec(s.pressure_a), to_vec(s.pressure_b)};
}

bool commanding(safety::Mode m) { return m == safety::Mode::hold || m == safety::Mode::track; }

}  // namespace

FirmwareNode::FirmwareNode(const Model& model, const control::Task& task, const FirmwareNodeConfig& config,
                           hal::FirmwareCanPort& port, telemetry::TelemetrySink* telemetry)
    : task_(task),
      config_(config),
      port_(port),
      telemetry_(telemetry),
      machine_(config.controller.watchdog_timeout),
      supervisor_(model.machine, config.controller.supervisor, config.controller.period),
      path_(task, model.machine, config.controller.path_clock, config.controller.period),
      counters_(config.controller.period),
      step_(model, config_, supervisor_, counters_),
      period_(config.controller.period) {}

FirmwareNode::~FirmwareNode() = default;

void FirmwareNode::begin_cycle() {
  ++cycle_;
  complete_ = false;
  port_.send_sync(cycle_);
  if (cycle_ % hal::kHeartbeatPeriodCycles == 0) port_.send_heartbeat(static_cast<std::uint8_t>(machine_.mode()));
  // FW_EMERGENCY is IfActive in the DBC: sent on entry to the safe state (end_cycle) and repeated
  // every 10 ms while it lasts, so a node that missed the first frame still learns of the stop.
  if (supervisor_.stop_frame_due(cycle_, machine_.mode(), hal::kEmergencyRepeatCycles)) send_stop_frame();
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
  // Read: the operator's commands (an operator's stop first decelerates a tracking machine along
  // its path) and the machine's own signals, each event taken once.
  const safety::CycleInputs in{t, cycle_, complete, machine_.mode()};
  if (supervisor_.take_operator(in, sensors_.supervisor_pending, path_.stopping())) path_.begin_stop(t);
  sensors_.supervisor_pending = 0;
  supervisor_.take_signals(in, sensors_, path_.stop_moving(t));
  sensors_.plant_emergency = false;
  counters_.read.record_ns(hal::monotonic_now_ns() - start_ns);

  const safety::Transition transition = step_mode(in);
  compute_command(transition);
  const std::int64_t write_start_ns = hal::monotonic_now_ns();
  port_.write(command_);
  const std::int64_t write_end_ns = hal::monotonic_now_ns();
  counters_.write.record_ns(write_end_ns - write_start_ns);
  if (tracking()) measured_.add(to_vec(sensors_.position), desired_.q);
  publish_cycle(transition);
  const std::int64_t end_ns = hal::monotonic_now_ns();
  if (telemetry_ != nullptr) counters_.telemetry.record_ns(end_ns - write_end_ns);
  counters_.cycle.record_ns(end_ns - start_ns);
}

safety::Transition FirmwareNode::step_mode(const safety::CycleInputs& in) {
  const double t = in.t;
  // A stop request decelerates a tracking machine along its path first; it holds once the path is at rest.
  if (stop_requested_ && tracking() && !path_.stopping()) path_.begin_stop(t);
  safety::StateMachineInputs sm;
  sm.t = t;
  sm.have_valid_frame = have_valid_;
  sm.last_valid_frame_time = last_valid_time_;
  // The task starts once. After a safe stop the machine holds where it is when the sensors are back:
  // resuming would restart the path from its first point, a step command nobody asked for.
  sm.track_requested = t >= config_.track_delay && supervisor_.safe_stops() == 0 &&
                       (supervisor_.start_received() || !config_.wait_for_start);
  sm.stop_requested = stop_requested_ && !path_.stop_moving(t);
  // Once the task has ended it stays ended: hold must not re-enter track and restart the path (the
  // path time before the transition: one into track restarts the path's clock).
  sm.trajectory_finished = finished_ || (tracking() && path_.time_at(t) >= task_.end_time());
  sm.fault = supervisor_.fault_pending();
  sm.acknowledged = supervisor_.acknowledged();
  const safety::Transition transition = machine_.step(sm);
  transition_ = transition;
  if (transition.changed && transition.from == safety::Mode::track) path_.cancel_stop();
  if (transition.changed && transition.to == safety::Mode::hold) {
    // From track, hold where the path was (its last point when it ended): the desired pose never
    // steps. From start-up or a safe stop, hold where the machine is.
    held_q_ = transition.from == safety::Mode::track ? desired_.q : to_vec(sensors_.position);
    if (transition.from == safety::Mode::track && !finished_ && sm.trajectory_finished) {
      Vec4 qd_end, qdd_end;
      task_.trajectory.evaluate(task_.end_time(), held_q_, qd_end, qdd_end);
      finished_ = true;
      finish_time_ = t;
    }
  }
  if (transition.changed && transition.to == safety::Mode::track) path_.start(t);
  switch (supervisor_.on_transition(transition, in, last_valid_time_)) {
    case safety::Supervisor::StopAction::send_stop: send_stop_frame(); break;
    // Leaving an acknowledged stop: the machine's emergency latch is released (EmergencyStop = 0,
    // no fault) so it obeys the commands again.
    case safety::Supervisor::StopAction::release: port_.send_fault(false, 0); break;
    case safety::Supervisor::StopAction::none: break;
  }
  if (machine_.mode() == safety::Mode::safe_stop &&
      supervisor_.check_standstill(machine_.mode(), cycle_, in.complete,
                                   step_.stage().flow_measurement(to_vec(sensors_.position), pressures_of(sensors_)),
                                   valve_interface() && sensors_.pressure_valid))
    send_stop_frame();
  return transition;
}

void FirmwareNode::compute_command(const safety::Transition& transition) {
  const safety::Mode mode = machine_.mode();
  const double t = time();
  command_.cycle = cycle_;
  command_.firmware_mode = static_cast<std::uint8_t>(mode);
  // No valid sensors (or a fault): the safe state, valves centred.
  if (!commanding(mode)) return step_.centre(t, sensors_, command_);
  // Entering hold/track after a stop or at start: the estimator, the law and the valve stage restart.
  step_.estimate(sensors_, transition.changed && (transition.from == safety::Mode::safe_stop ||
                                                  transition.from == safety::Mode::wait_sensors));
  if (mode == safety::Mode::track)
    path_time_ = path_.desired(t, desired_.q, desired_.qd, desired_.qdd);
  else
    desired_ = DesiredMotion{held_q_, Vec4::Zero(), Vec4::Zero()};
  step_.update(t, mode, transition.changed, commanding(transition.from), complete_, sensors_, desired_, command_);
}

void FirmwareNode::send_stop_frame() {
  const safety::StopFrame f = supervisor_.stop_frame();
  port_.send_fault(f.emergency, static_cast<std::uint16_t>(f.code));
}

void FirmwareNode::send_safe_command(safety::FirmwareFault why) {
  command_.mode = hal::CommandMode::valve;
  command_.value = {0, 0, 0, 0};
  command_.cycle = cycle_;
  command_.firmware_mode = static_cast<std::uint8_t>(safety::Mode::safe_stop);
  port_.write(command_);
  const safety::StopFrame f = supervisor_.exit_frame(why, machine_.mode());
  port_.send_fault(f.emergency, static_cast<std::uint16_t>(f.code));
  safe_command_sent_ = true;
}

void FirmwareNode::record_wakeup(std::int64_t interval_ns, std::uint64_t overruns, std::uint64_t skipped) {
  counters_.interval.record_ns(interval_ns);
  counters_.deadline_overruns = overruns;
  counters_.skipped_deadlines = skipped;
  supervisor_.record_wakeup(overruns, skipped, machine_.mode(), time() + period_);
}

void FirmwareNode::publish_cycle(const safety::Transition& transition) {
  safety::FaultEvent e;
  if (telemetry_ == nullptr) {
    while (supervisor_.next_event(e)) {
    }
    return;
  }
  while (supervisor_.next_event(e)) publish_fault(e.code, e.severity, e.active, e.text);
  const std::int64_t utime = this->utime();
  const auto mode = static_cast<std::int8_t>(machine_.mode());
  telemetry_->publish(telemetry::Channel::command,
                      command_message(utime, mode, step_.controller_id(), static_cast<std::int8_t>(config_.controller.command_interface),
                                      command_, step_.stage(), step_.output()));
  telemetry_->publish(telemetry::Channel::controller,
                      controller_message(utime, mode, step_.controller_id(), desired_.q, desired_.qd, step_.output(), config_.theta_known ? &config_.theta_true : nullptr));
  if (transition.changed) {
    const bool stop = transition.to == safety::Mode::safe_stop;
    char text[sizeof(exlcm::fault_t::text)];
    // A longer text is cut at the message's field (fault_t.text).
    if (std::snprintf(text, sizeof text, "%s -> %s: %s%s%s", safety::to_string(transition.from), safety::to_string(transition.to),
                      transition.reason, stop ? ": " : "", stop ? supervisor_.last_fault_text() : "") < 0)
      text[0] = 0;
    publish_fault(stop ? supervisor_.last_fault() : safety::FirmwareFault::none, stop ? 2 : 0, stop, text);
  }
  // The cycle's scope: read to telemetry encoded, the periodic counter messages included, a step a
  // cycle from each kCounterPeriod-th on.
  const std::uint64_t step = cycle_ % diagnostics::kCounterPeriod;
  if (cycle_ >= diagnostics::kCounterPeriod && step < static_cast<std::uint64_t>(diagnostics::kCounterSteps))
    counters_.publish_step(static_cast<int>(step), *telemetry_, port_, time(), this->utime());
}

void FirmwareNode::publish_fault(safety::FirmwareFault code, std::int8_t severity, bool active, const char* text) {
  exlcm::fault_t f{};
  f.utime = utime();
  f.code = static_cast<std::int32_t>(code);
  f.severity = severity;
  f.active = active;
  std::snprintf(reinterpret_cast<char*>(f.text), sizeof(f.text), "%s", text);
  telemetry_->publish(telemetry::Channel::fault, f);
}

void FirmwareNode::publish_counters(bool after_exit_command) {
  if (telemetry_ == nullptr) return;
  // The exit's safe command goes out after the last cycle: its frames' bus time falls in the period
  // after it, the window EXC_CAN_STATS's load is taken over.
  const double window_end = time() + (after_exit_command ? period_ : 0.0);
  counters_.publish(*telemetry_, port_, window_end, utime() + (after_exit_command ? std::llround(period_ * 1e6) : 0));
}

void FirmwareNode::scan_state(diagnostics::SubnormalScan& scan) const {
  // The law, the estimator and the stages show their state through the laws' interface.
  struct Scan final : control::StateVisitor {
    explicit Scan(diagnostics::SubnormalScan& s) : scan(s) {}
    void visit(const char* name, const double* values, std::size_t count) override { scan.visit(name, values, count); }
    diagnostics::SubnormalScan& scan;
  } v(scan);
  // What came in and went out, the path and the hold: each type visits its own values.
  hal::visit_state(sensors_, scan);
  hal::visit_state(command_, scan);
  visit_state(desired_, scan);
  scan.visit("held q", held_q_);
  // The law, its output and the stages after it.
  step_.visit_state(v);
}

}  // namespace exc::app
