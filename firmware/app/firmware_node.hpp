#pragma once
// The firmware's 1 kHz cycle, wired (PX4 module style: the control law, the supervision and the
// stages after the law are libraries; this wires bus, state machine and telemetry to them):
//   begin_cycle(): send SYNC(k) (+ heartbeat)              -> the plant steps once and answers
//   end_cycle():   read + validate sensors -> supervisor (operator, machine signals) -> state
//                  machine -> estimate -> path -> control law -> supervisor's checks -> actuation
//                  stage (blend and lag lead, or the valve stage) -> the valve stage's monitors ->
//                  write commands -> telemetry (estimate to the monitors: the control step,
//                  control_step.hpp, timed as one stage and in parts)
// Time is the cycle count times the period, so a run is deterministic and the plant's time is the
// firmware's. Nothing here allocates, locks or blocks after construction.
#include <cmath>
#include <cstdint>

#include "app/control_step.hpp"
#include "diagnostics/loop_counters.hpp"
#include "diagnostics/subnormal_scan.hpp"
#include "app/tracking_metrics.hpp"
#include "control/task/path_clock.hpp"
#include "diagnostics/perf_counter.hpp"
#include "control/task/task.hpp"
#include "app/firmware_node_config.hpp"
#include "hal/can_ports.hpp"
#include "model/model.hpp"
#include "safety/supervisor.hpp"

namespace exc::telemetry {
class TelemetrySink;
}

namespace exc::app {

class FirmwareNode {
 public:
  FirmwareNode(const Model& model, const control::Task& task, const FirmwareNodeConfig& config,
               hal::FirmwareCanPort& port, telemetry::TelemetrySink* telemetry);
  ~FirmwareNode();
  FirmwareNode(const FirmwareNode&) = delete;
  FirmwareNode& operator=(const FirmwareNode&) = delete;

  // Starts cycle k (k = previous + 1): SYNC, the heartbeat every 100 cycles, a standing stop's
  // FW_EMERGENCY every 10 ms.
  void begin_cycle();
  // Drains the bus into the sensor state; true once the complete sensor set of this cycle is in.
  // Callers on a real bus call it while waiting for the plant's answer; end_cycle() calls it too.
  bool receive();
  // Completes the cycle once the plant had its chance to answer: read, update, write, telemetry.
  void end_cycle();
  // A stop from outside the control loop (a signal, the caller): a tracking machine decelerates
  // along its path (control/task/path_stop.hpp, controller.stop_ramp_time) and then holds where the path
  // came to rest; the node stays in hold. Real-time safe (sets a flag). An operator's SUPERVISOR
  // stop is stronger: the same deceleration, then a controlled stop that latches until acknowledged.
  void request_stop() { stop_requested_ = true; }
  bool stop_requested() const { return stop_requested_; }
  // An operator acknowledges the latched stop (the SUPERVISOR frame's acknowledge, or a caller on
  // the operator's behalf), taken on the next cycle (safety/supervisor.hpp). Real-time safe.
  void acknowledge() { supervisor_.acknowledge(); }
  // The last frames of a program that leaves (end of run, a signal, an error): valves centred
  // (CMD_VALVE of zeros, this cycle's counter) and FW_EMERGENCY with `why` (exited: controlled stop;
  // fatal_error: emergency stop) unless a safe state already stands, whose fault it repeats. The
  // machine keeps the centred valves until its own command watchdog holds it. Idempotent per cycle.
  void send_safe_command(safety::FirmwareFault why);
  bool safe_command_sent() const { return safe_command_sent_; }
  // A real-time loop reports each wake-up: the interval since the previous one, and its sleeper's
  // deadline counters (published on EXC_TIMING, stage 5; missed deadlines are the supervisor's).
  void record_wakeup(std::int64_t interval_ns, std::uint64_t overruns, std::uint64_t skipped);
  // Publishes the timing and CAN counters now (also done every 100 cycles); after_exit_command: the
  // last ones, after the exit's safe command, whose frames take the period after the last cycle.
  void publish_counters(bool after_exit_command = false);
  // Every value the node carries from one cycle to the next, for a look for subnormals
  // (docs/floating-point.md). Not on the loop's path.
  void scan_state(diagnostics::SubnormalScan& scan) const;

  // Faults, stops, monitors, the operator link: the supervisor's record.
  const safety::Supervisor& supervisor() const { return supervisor_; }
  const safety::Transition& last_transition() const { return transition_; }  // changed == false: kept its mode
  // Tracking figures as the firmware measures them (sensed q_a against q_d, while tracking).
  const TrackingMetrics& measured_tracking() const { return measured_; }
  std::uint64_t cycle() const { return cycle_; }
  double time() const { return static_cast<double>(cycle_) * period_; }
  // time() in whole microseconds, rounded (telemetry's utime): truncating cycle x period x 1e6 gave
  // 1024999 for cycle 1025 at 1 ms, so consecutive messages were 999 and 1001 us apart.
  std::int64_t utime() const { return std::llround(time() * 1e6); }
  safety::Mode mode() const { return machine_.mode(); }
  bool tracking() const { return machine_.mode() == safety::Mode::track; }
  // The trajectory ran to its end (the node then holds its last point until the run ends or a stop
  // arrives; it never restarts the task by itself), and the loop time when it did (s).
  bool trajectory_finished() const { return finished_; }
  double finish_time() const { return finish_time_; }
  // The trajectory time tracked this cycle (task clock); negative when not tracking.
  double task_time() const { return tracking() ? path_time_ : -1.0; }
  bool stopping_on_path() const { return path_.stopping(); }  // a stop along the path is under way
  // Desired q_a of the last cycle (valid while tracking or holding).
  const Vec4& q_desired() const { return desired_.q; }
  const hal::SensorState& sensors() const { return sensors_; }
  bool has_sensors() const { return have_valid_; }  // a complete, valid sensor set arrived at least once
  const control::ControlOutput& last_output() const { return step_.output(); }
  // The valve stage's last command (valve interface; zeros otherwise).
  const control::ValveCommand& last_valve_command() const { return step_.stage().last_valve_command(); }
  bool valve_interface() const { return config_.controller.command_interface == control::CommandInterface::valve; }
  const hal::CommandState& last_command() const { return command_; }
  // The loop's timing counters by stage (loop_counters.hpp); the control computation (estimate, path,
  // law, the stages after it and the monitors), the whole end_cycle and a real-time loop's interval.
  const diagnostics::LoopCounters& counters() const { return counters_; }
  const diagnostics::PerfCounter& control_timing() const { return counters_.update; }
  const diagnostics::PerfCounter& cycle_timing() const { return counters_.cycle; }
  const diagnostics::PerfCounter& interval_timing() const { return counters_.interval; }

 private:
  // The state machine's step for this cycle's inputs, what the transition changes (the path, the
  // hold, the latched stop) and the standstill monitor of a standing stop.
  safety::Transition step_mode(const safety::CycleInputs& in);
  // The command of the mode: centred valves, or estimate, path, law and the stages after it, with
  // the supervisor's checks of each.
  void compute_command(const safety::Transition& transition);
  void send_stop_frame();
  // The cycle's telemetry: the supervisor's fault events, EXC_COMMAND, EXC_CONTROLLER, a transition's
  // EXC_FAULT and every kCounterPeriod cycles the counters.
  void publish_cycle(const safety::Transition& transition);
  void publish_fault(safety::FirmwareFault code, std::int8_t severity, bool active, const char* text);

  const control::Task& task_;
  FirmwareNodeConfig config_;
  hal::FirmwareCanPort& port_;
  telemetry::TelemetrySink* telemetry_;
  safety::ControlStateMachine machine_;
  safety::Supervisor supervisor_;
  control::PathClock path_;
  diagnostics::LoopCounters counters_;
  ControlStep step_;  // estimate, law, the stages after it and their checks

  double period_;
  std::uint64_t cycle_ = 0;
  bool have_valid_ = false;
  bool complete_ = false;
  double last_valid_time_ = -1e300;
  safety::Transition transition_;
  TrackingMetrics measured_;
  double path_time_ = 0;  // the task time tracked this cycle (slowed by a stop along the path)
  bool finished_ = false;
  double finish_time_ = 0;
  bool stop_requested_ = false;
  bool safe_command_sent_ = false;
  Vec4 held_q_ = Vec4::Zero();
  DesiredMotion desired_;
  hal::SensorState sensors_;
  hal::CommandState command_;
};

}  // namespace exc::app
