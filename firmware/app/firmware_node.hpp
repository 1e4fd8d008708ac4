#pragma once
// The firmware's 1 kHz cycle, wired (PX4 module style: the control law is a library, this only
// wires bus, state machine, estimator, trajectory, controller and telemetry):
//   begin_cycle(): send SYNC(k) (+ heartbeat)              -> the plant steps once and answers
//   end_cycle():   read + validate sensors -> watchdog/state machine -> estimate -> trajectory
//                  -> control law -> saturate/blend -> actuator-lag lead -> write commands
//                  -> telemetry
// Time is the cycle count times the period, so a run is deterministic and the plant's time is the
// firmware's. Nothing here allocates, locks or blocks after construction.
#include <cmath>
#include <cstdint>
#include <memory>

#include "model/actuator_friction.hpp"
#include "control/actuator_lag_compensator.hpp"
#include "control/command_blender.hpp"
#include "control/path_clock.hpp"
#include "control/control_types.hpp"
#include "control/controller_config.hpp"
#include "control/perf_counter.hpp"
#include "control/state_estimator.hpp"
#include "control/task.hpp"
#include "control/valve_inner_loop.hpp"
#include "hal/can_ports.hpp"
#include "app/can_stats_message.hpp"
#include "app/firmware_node_config.hpp"
#include "app/subnormal_scan.hpp"
#include "safety/supervisor.hpp"
#include "app/tracking_metrics.hpp"
#include "model/model.hpp"

namespace exc::telemetry {
class TelemetryPublisher;
}

namespace exc::app {

// Cycles between the node's counter messages (EXC_TIMING per stage, EXC_CAN_STATS).
inline constexpr int kCounterPeriod = 100;
// The stages the node publishes on EXC_TIMING each time (publish_counters): whole cycle, read, update,
// write, telemetry encode; a real-time loop adds its wake-up interval.
inline constexpr int kTimingStages = 5;
class FirmwareNode {
 public:
  FirmwareNode(const Model& model, const control::Task& task, const FirmwareNodeConfig& config,
               hal::FirmwareCanPort& port, telemetry::TelemetryPublisher* telemetry);
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
  // along its path (control/path_stop.hpp, controller.stop_ramp_time) and then holds where the path
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
  void scan_state(SubnormalScan& scan) const;

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
  const Vec4& q_desired() const { return q_d_; }
  const hal::SensorState& sensors() const { return sensors_; }
  bool has_sensors() const { return have_valid_; }  // a complete, valid sensor set arrived at least once
  const control::ControlOutput& last_output() const { return out_; }
  // The valve stage's last command (valve interface; zeros otherwise).
  const control::ValveCommand& last_valve_command() const { return valves_.last(); }
  bool valve_interface() const { return config_.controller.command_interface == control::CommandInterface::valve; }
  const hal::CommandState& last_command() const { return command_; }
  // The control computation (estimate, path, law, the stages after it and the monitors), the whole
  // end_cycle (read, compute, write, telemetry encoding with the counter messages every 100 cycles),
  // and a real-time loop's wake-up interval.
  const control::PerfCounter& control_timing() const { return control_timing_; }
  const control::PerfCounter& cycle_timing() const { return cycle_timing_; }
  const control::PerfCounter& interval_timing() const { return interval_timing_; }

 private:
  void compute_command(const safety::Transition& transition);
  void centre_valves();
  // The efforts the machine applied over the last cycle as far as the firmware knows them: measured
  // (valve interface, from the pressures) or the delivered-effort model of the last command.
  control::AppliedEffort applied_effort() const;
  // The nominal machine's seal friction at velocity v and these chamber pressures (actuator_friction.hpp).
  Vec4 seal_friction(const Vec4& v, const Vec4& p_a, const Vec4& p_b) const;
  // The valve interface: the law's effort through the force loop (or a flow law's velocity) to the
  // spools' pilot pressures.
  void command_valves(const Vec4& q);
  safety::FlowMeasurement flow_measurement() const;
  void send_stop_frame();
  void publish_cycle();
  void publish_events();
  void publish_fault(safety::FirmwareFault code, std::int8_t severity, bool active, const char* text);

  const Model& model_;
  ActuatorFriction friction_;  // the nominal machine's (start-up)
  const control::Task& task_;
  FirmwareNodeConfig config_;
  hal::FirmwareCanPort& port_;
  telemetry::TelemetryPublisher* telemetry_;
  std::unique_ptr<control::Controller> controller_;
  std::int8_t controller_id_;  // the law's number in telemetry (ControllerRegistry::id_of)
  control::StateEstimator estimator_;
  safety::ControlStateMachine machine_;
  safety::Supervisor supervisor_;
  control::PathClock path_;
  control::CommandBlender blender_;
  control::ActuatorLagCompensator lag_compensator_;
  control::ValveInnerLoop valves_;
  control::PerfCounter control_timing_, cycle_timing_;
  control::PerfCounter read_timing_, write_timing_, telemetry_timing_, interval_timing_;
  std::uint64_t deadline_overruns_ = 0, skipped_deadlines_ = 0;
  BusLoadWindow bus_load_;

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
  Vec4 q_d_ = Vec4::Zero(), qd_d_ = Vec4::Zero(), qdd_d_ = Vec4::Zero();
  Vec4 last_sent_ = Vec4::Zero();
  hal::SensorState sensors_;
  hal::CommandState command_;
  control::ControlOutput out_;
};

}  // namespace exc::app
