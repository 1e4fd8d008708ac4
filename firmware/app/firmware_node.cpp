#include "app/firmware_node.hpp"

#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

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

Vec4 to_vec(const std::array<double, 4>& a) { return Vec4(a[0], a[1], a[2], a[3]); }

// Refuses a law the command interface cannot carry (a flow law on the effort interface) before it
// is built: std::invalid_argument naming both.
std::unique_ptr<control::Controller> checked_controller(const Model& model, const control::ControllerConfig& config) {
  const control::ControllerEntry& law = control::controller_registry().at(config.law);
  if (const std::string why = control::interface_misfit(law, config.command_interface); !why.empty())
    throw std::invalid_argument("controller " + why + " (the scene's controller.command_interface is " +
                                control::kCommandInterfaces.name_of(config.command_interface) + ")");
  return law.make(model, config);
}

safety::SupervisorSettings supervisor_settings(const control::ControllerConfig& c) {
  safety::SupervisorSettings s;
  s.period = c.period;
  s.supervisor_timeout = c.supervisor_timeout;
  s.max_missed_deadlines = c.max_missed_deadlines;
  s.tracking_error_limit = c.tracking_error_limit;
  s.plausibility = c.plausibility;
  s.pressure_plausibility = c.pressure_plausibility;
  return s;
}

}  // namespace

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
      supervisor_(model.machine, supervisor_settings(config.controller)),
      path_(task, model.machine, config.controller),
      blender_(config.controller.blend_time),
      lag_compensator_(config.controller.actuator_lag, config.controller.actuator_lag_target,
                       config.controller.period, control::effort_limits_of(model.machine)),
      valves_(control::valve_loop_model(model.machine), config.controller.valves, config.controller.period),
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
  // its path) and the machine's own signals, each taken once.
  const safety::CycleInputs in{t, cycle_, complete, machine_.mode()};
  if (supervisor_.take_operator(in, sensors_.supervisor_pending, path_.stopping())) path_.begin_stop(t);
  sensors_.supervisor_pending = 0;
  supervisor_.take_signals(in, sensors_, path_.stop_moving(t));
  sensors_.plant_emergency = false;
  const std::int64_t read_ns = hal::monotonic_now_ns();
  read_timing_.record_ns(read_ns - start_ns);

  // A stop request decelerates a tracking machine along its path first; it holds once the path is at rest.
  if (stop_requested_ && tracking() && !path_.stopping()) path_.begin_stop(t);
  // The path time before the transition, for the end-of-task test; compute_command takes it again
  // after it (a transition into track restarts the path's clock).
  const double tau = path_.time_at(t);
  safety::StateMachineInputs sm;
  sm.t = t;
  sm.have_valid_frame = have_valid_;
  sm.last_valid_frame_time = last_valid_time_;
  // The task starts once. After a safe stop the machine holds where it is when the sensors are back:
  // resuming would restart the path from its first point, a step command nobody asked for.
  sm.track_requested = t >= config_.track_delay && supervisor_.safe_stops() == 0 &&
                       (supervisor_.start_received() || !config_.wait_for_start);
  sm.stop_requested = stop_requested_ && !path_.stop_moving(t);
  // Once the task has ended it stays ended: hold must not re-enter track and restart the path.
  sm.trajectory_finished = finished_ || (tracking() && tau >= task_.end_time());
  sm.fault = supervisor_.fault_pending();
  sm.acknowledged = supervisor_.acknowledged();
  const safety::Transition transition = machine_.step(sm);
  transition_ = transition;
  if (transition.changed && transition.from == safety::Mode::track) path_.cancel_stop();
  if (transition.changed && transition.to == safety::Mode::hold) {
    // From track, hold where the path was (its last point when it ended): the desired pose never
    // steps. From start-up or a safe stop, hold where the machine is.
    held_q_ = transition.from == safety::Mode::track ? q_d_ : to_vec(sensors_.position);
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
      supervisor_.check_standstill(machine_.mode(), cycle_, complete, flow_measurement(), valve_interface() && sensors_.pressure_valid))
    send_stop_frame();

  compute_command(transition);
  const std::int64_t write_start_ns = hal::monotonic_now_ns();
  port_.write(command_);
  const std::int64_t write_end_ns = hal::monotonic_now_ns();
  write_timing_.record_ns(write_end_ns - write_start_ns);
  if (tracking()) measured_.add(to_vec(sensors_.position), q_d_);
  if (telemetry_ != nullptr) {
    publish_events();
    publish_cycle();
    if (transition.changed) {
      const bool stop = transition.to == safety::Mode::safe_stop;
      char text[sizeof(exlcm::fault_t::text)];
      std::snprintf(text, sizeof text, "%s -> %s: %s%s%s", safety::to_string(transition.from), safety::to_string(transition.to),
                    transition.reason, stop ? ": " : "", stop ? supervisor_.last_fault_text() : "");
      publish_fault(stop ? supervisor_.last_fault() : safety::FirmwareFault::none, stop ? 2 : 0, stop, text);
    }
    // The cycle's scope: read to telemetry encoded, the periodic counter messages included.
    if (cycle_ % kCounterPeriod == 0) publish_counters();
  } else {
    safety::FaultEvent dropped;
    while (supervisor_.next_event(dropped)) {
    }
  }
  const std::int64_t end_ns = hal::monotonic_now_ns();
  if (telemetry_ != nullptr) telemetry_timing_.record_ns(end_ns - write_end_ns);
  cycle_timing_.record_ns(end_ns - start_ns);
}

void FirmwareNode::centre_valves() {
  // No valid sensors (or a fault): the safe state is valves centred, i.e. zero cylinder flow and
  // the swing brake; the plant holds the machine where it is.
  command_.mode = hal::CommandMode::valve;
  command_.value = {0, 0, 0, 0};
  last_sent_.setZero();
  supervisor_.update_pump_warning(time(), false, 0);  // centred valves ask nothing
  supervisor_.idle_pressures();
}

void FirmwareNode::compute_command(const safety::Transition& transition) {
  const safety::Mode mode = machine_.mode();
  command_.cycle = cycle_;
  command_.firmware_mode = static_cast<std::uint8_t>(mode);
  if (mode != safety::Mode::hold && mode != safety::Mode::track) return centre_valves();
  const std::int64_t start_ns = hal::monotonic_now_ns();
  const double t = time();
  const Vec4 q = to_vec(sensors_.position);
  const Vec4 qd = to_vec(sensors_.velocity);
  // Entering hold/track after a stop or at start: the estimator, the law and the lag model restart.
  const bool restarted = transition.changed && (transition.from == safety::Mode::safe_stop ||
                                                transition.from == safety::Mode::wait_sensors);
  if (restarted) {
    estimator_.reset(q, qd);
    controller_->reset();
    valves_.reset();
  } else {
    estimator_.update(q, qd);
  }
  if (mode == safety::Mode::track) {
    path_time_ = path_.desired(t, q_d_, qd_d_, qdd_d_);
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
  supervisor_.check_law(t, out_.status == ModelStatus::ok && out_.tau.allFinite(), out_.e,
                        mode == safety::Mode::track && transition.changed);

  // Bumpless: entering hold/track from another effort-commanding mode starts from the last command.
  if (transition.changed && (transition.from == safety::Mode::hold || transition.from == safety::Mode::track))
    blender_.on_switch(t, last_sent_, out_.tau);
  if (valve_interface()) {
    supervisor_.check_pressures(t, !restarted && sensors_.pressure_valid, complete_, sensors_);
    command_valves(q);
    supervisor_.check_flow(t, !restarted, valves_.last().velocity, flow_measurement(), estimator_.velocity());
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

safety::FlowMeasurement FirmwareNode::flow_measurement() const {
  safety::FlowMeasurement m;
  m.position = to_vec(sensors_.position);
  // Without pressures (or valves) the compression is unknown: the monitor then sees the motion alone.
  if (!valve_interface() || !sensors_.pressure_valid) return m;
  const Vec4 p_a = to_vec(sensors_.pressure_a), p_b = to_vec(sensors_.pressure_b);
  m.compression = valves_.measured_force(p_a, p_b).cwiseQuotient(valves_.hydraulic_stiffness(m.position));
  m.at_relief = valves_.at_relief(p_a, p_b);
  return m;
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
  interval_timing_.record_ns(interval_ns);
  deadline_overruns_ = overruns;
  skipped_deadlines_ = skipped;
  supervisor_.record_wakeup(overruns, skipped, machine_.mode(), time() + period_);
}

void FirmwareNode::publish_events() {
  safety::FaultEvent e;
  while (supervisor_.next_event(e)) publish_fault(e.code, e.severity, e.active, e.text);
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

void FirmwareNode::command_valves(const Vec4& q) {
  const Vec4 p_a = to_vec(sensors_.pressure_a), p_b = to_vec(sensors_.pressure_b);
  valves_.set_holding(machine_.mode() == safety::Mode::hold, out_.e);
  const control::ValveCommand* v = nullptr;
  if (out_.velocity_command) {
    v = &valves_.from_velocity(out_.velocity, q, p_a, p_b);
  } else {
    // The force loop closes on the measured chamber pressures: without them it would drive the
    // valves blind. Fault (the safe state centres the valves next cycle) rather than guess.
    supervisor_.require_pressures(time(), sensors_.pressure_valid);
    const Vec4 tau = blender_.apply(time(), out_.tau);
    last_sent_ = tau;
    const Vec4 v_ff = qd_d_ - valves_.settings().position_gain.cwiseProduct(out_.e);
    // The cylinders push what the mechanism needs plus what their seals take (the nominal machine's
    // friction, signed by the velocity the valves are asked for, which does not chatter with the
    // sensors' noise; applied_effort() takes it back out of the measured force).
    v = &valves_.from_force(tau + seal_friction(v_ff, p_a, p_b), v_ff, q, p_a, p_b);
  }
  supervisor_.update_pump_warning(time(), v->pump_limited, v->demanded_flow);
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

void FirmwareNode::publish_fault(safety::FirmwareFault code, std::int8_t severity, bool active, const char* text) {
  if (telemetry_ == nullptr) return;
  exlcm::fault_t f{};
  f.utime = utime();
  f.code = static_cast<std::int32_t>(code);
  f.severity = severity;
  f.active = active;
  std::snprintf(reinterpret_cast<char*>(f.text), sizeof(f.text), "%s", text);
  telemetry_->publish(telemetry::Channel::fault, f);
}

}  // namespace exc::app
