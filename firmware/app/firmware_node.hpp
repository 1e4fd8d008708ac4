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
#include "control/path_stop.hpp"
#include "control/pump_pacing.hpp"
#include "control/control_types.hpp"
#include "control/controller_config.hpp"
#include "control/frozen_position.hpp"
#include "control/perf_counter.hpp"
#include "control/pressure_plausibility.hpp"
#include "control/state_estimator.hpp"
#include "control/state_machine.hpp"
#include "control/task.hpp"
#include "control/valve_inner_loop.hpp"
#include "hal/can_ports.hpp"
#include "app/can_stats_message.hpp"
#include "app/creep_window.hpp"
#include "app/firmware_faults.hpp"
#include "app/subnormal_scan.hpp"
#include "app/tracking_metrics.hpp"
#include "model/model.hpp"

namespace exc::telemetry {
class TelemetryPublisher;
}

namespace exc::app {

struct FirmwareNodeConfig {
  control::ControllerConfig controller;  // its law names the control law the node runs
  Terrain site_map;               // the scene's ground, for the soil-contact estimate (control/soil_contact.hpp)
  double track_delay = 0.05;      // s held at the first sensor reading before tracking starts
  // Hold until an operator's start (SUPERVISOR Command = start) before tracking; false: the task
  // starts by itself after track_delay (the default: runs without an operator station).
  bool wait_for_start = false;
  // Simulation only: the plant's true soil parameters, for telemetry and the Lyapunov value.
  bool theta_known = false;
  Vec6 theta_true = Vec6::Zero();
};

inline constexpr int kPumpWarningCycles = 20;
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

  // Starts cycle k (k = previous + 1): SYNC, and the heartbeat every 100 cycles.
  void begin_cycle();
  // Drains the bus into the sensor state; true once the complete sensor set of this cycle is in.
  // Callers on a real bus call it while waiting for the plant's answer; end_cycle() calls it too.
  bool receive();
  // Completes the cycle once the plant had its chance to answer.
  void end_cycle();
  // A stop from outside the control loop (a signal, the caller): a tracking machine decelerates
  // along its path (control/path_stop.hpp, controller.stop_ramp_time) and then holds where the path
  // came to rest; the node stays in hold. Real-time safe (sets a flag). An operator's SUPERVISOR
  // stop is stronger: the same deceleration, then a controlled stop that latches
  // (FirmwareFault::operator_stop) until acknowledged.

  void request_stop() { stop_requested_ = true; }
  bool stop_requested() const { return stop_requested_; }
  // An operator acknowledges the latched stop (the SUPERVISOR frame's acknowledge, or a caller on
  // the operator's behalf). Taken on the next cycle: the node leaves its safe state for hold where
  // the machine is when the sensors are fresh and no fault stands; an acknowledge while a condition
  // stands is spent (a person acknowledges what they see gone). Real-time safe (sets a flag).
  void acknowledge() { acknowledge_requested_ = true; }
  // An operator's start arrived (SUPERVISOR Command = start): a node set to wait_for_start may track.
  bool start_received() const { return start_received_; }
  // The last frames of a program that leaves (end of run, a signal, an error): valves centred
  // (CMD_VALVE of zeros, this cycle's counter) and FW_EMERGENCY with `why` (exited: controlled stop;
  // fatal_error: emergency stop) unless a safe state already stands, whose fault it repeats. The
  // machine keeps the centred valves until its own command watchdog holds it. Idempotent per cycle.
  void send_safe_command(FirmwareFault why);
  bool safe_command_sent() const { return safe_command_sent_; }
  // The last mode transition (changed == false when the last cycle kept its mode).
  const control::Transition& last_transition() const { return transition_; }
  // Tracking figures as the firmware measures them (sensed q_a against q_d, while tracking).
  const TrackingMetrics& measured_tracking() const { return measured_; }

  std::uint64_t cycle() const { return cycle_; }
  double time() const { return static_cast<double>(cycle_) * period_; }
  // time() in whole microseconds, rounded (telemetry's utime): truncating cycle x period x 1e6 gave
  // 1024999 for cycle 1025 at 1 ms, so consecutive messages were 999 and 1001 us apart.
  std::int64_t utime() const { return std::llround(time() * 1e6); }
  control::Mode mode() const { return machine_.mode(); }
  bool tracking() const { return machine_.mode() == control::Mode::track; }
  // The trajectory ran to its end (the node then holds its last point until the run ends or a
  // stop arrives; it never restarts the task by itself), and the loop time when it did (s).
  bool trajectory_finished() const { return finished_; }
  // The trajectory time being tracked this cycle (task clock: the first waypoint's time at the start
  // of tracking); negative when not tracking.
  double task_time() const { return machine_.mode() == control::Mode::track ? path_time_ : -1.0; }
  // A stop along the path is under way (the machine still tracks, on a slowing path).
  bool stopping_on_path() const { return path_stop_.active(); }
  double finish_time() const { return finish_time_; }
  // Desired and measured q_a of the last cycle (valid while tracking or holding).
  const Vec4& q_desired() const { return q_d_; }
  const hal::SensorState& sensors() const { return sensors_; }
  // A complete, valid sensor set has arrived at least once.
  bool has_sensors() const { return have_valid_; }
  const control::ControlOutput& last_output() const { return out_; }
  // The valve stage's last command (valve interface; zeros otherwise), and how many cycles its
  // openings asked the pumps for more flow than they give.
  const control::ValveCommand& last_valve_command() const { return valves_.last(); }
  // The velocity plausibility monitor (valve interface): expected velocities, residuals, margins.
  const control::VelocityPlausibility& plausibility() const { return plausibility_; }
  const control::FrozenPosition& frozen_position() const { return frozen_position_; }
  // The chamber pressures' plausibility monitor (valve interface): margins, longest frozen runs.
  const control::PressurePlausibility& pressure_plausibility() const { return pressure_monitor_; }
  std::uint64_t pump_limited_cycles() const { return pump_limited_cycles_; }
  // Pump-limited warnings raised so far, and the text of the last one raised or cleared.
  std::uint64_t pump_warnings() const { return pump_warnings_; }
  const char* last_warning_text() const { return warning_text_; }
  bool valve_interface() const { return config_.controller.command_interface == control::CommandInterface::valve; }
  const hal::CommandState& last_command() const { return command_; }
  // Time of the control computation (estimate + trajectory + control law), and of the whole
  // end_cycle: from its start (the plant has answered) through read, compute and write to the end of
  // the cycle's telemetry encoding (the counter messages every 100 cycles included).
  const control::PerfCounter& control_timing() const { return control_timing_; }
  const control::PerfCounter& cycle_timing() const { return cycle_timing_; }
  const control::PerfCounter& interval_timing() const { return interval_timing_; }
  // A real-time loop reports each wake-up: the interval since the previous one, and its sleeper's
  // deadline counters (published on EXC_TIMING, stage 5).
  void record_wakeup(std::int64_t interval_ns, std::uint64_t overruns, std::uint64_t skipped);
  std::uint64_t safe_stops() const { return safe_stops_; }
  // The stop the last safe state took (none before any), and whether any FW_EMERGENCY went out with
  // EmergencyStop = 1 (the campaign's `estop`).
  // A controlled stop escalates to the emergency stop when the machine does not come to a standstill
  // with its valves centred (kStandstill*: a stuck spool the velocity monitor could not tell).
  StopKind last_stop() const { return escalated_ ? StopKind::emergency : stop_of(fault_code_); }
  bool stop_escalated() const { return escalated_; }
  bool emergency_sent() const { return emergency_sent_; }
  // Consecutive real-time wake-ups after their deadline, as record_wakeup() last counted them.
  int missed_deadlines_in_a_row() const { return missed_in_a_row_; }
  // The fault of the last safe stop (none before any), and its description ("tracking error: swing
  // 0.1013 rad > limit 0.1 rad at t = 1.234 s").
  FirmwareFault last_fault() const { return fault_code_; }
  const char* last_fault_text() const { return fault_text_; }
  // When the fault of the last safe stop was detected (s; -1 before any): the cycle its condition was
  // first met (the safe state follows the next cycle), or for a sensor timeout the first cycle
  // without a valid sensor set (the watchdog's timeout later).
  double fault_detected_time() const { return fault_detected_time_; }
  // Publishes the timing and CAN counters now (also done every 100 cycles); after_exit_command: the
  // last ones, after the exit's safe command, whose frames take the period after the last cycle.
  void publish_counters(bool after_exit_command = false);
  // Every value the node carries from one cycle to the next (sensors, command, the law's output and
  // integrator, the estimator's filters, the lead compensators, the desired path), for a look for
  // subnormals (docs/floating-point.md). Not on the loop's path.
  void scan_state(SubnormalScan& scan) const;

 private:
  void compute_command(const control::Transition& transition);
  // The efforts the machine applied over the last cycle as far as the firmware knows them: measured
  // (valve interface, from the pressures) or the delivered-effort model of the last command.
  control::AppliedEffort applied_effort() const;
  // The effort the hydraulic machine's seals take at the estimated velocity (nominal friction).
  // The nominal machine's friction at velocity v and these chamber pressures (actuator_friction.hpp).
  Vec4 seal_friction(const Vec4& v, const Vec4& p_a, const Vec4& p_b) const;
  // The valve interface: the law's effort through the force loop (or a flow law's velocity) to the
  // spools' pilot pressures.
  void command_valves(const Vec4& q);
  void publish_cycle();
  // The pump-limited warning's debounce, raise and clear (FirmwareFault::pump_limited).
  void update_pump_warning(bool limited, double demanded_flow);
  void publish_fault(FirmwareFault code, std::int8_t severity, bool active, const char* text);
  // A fault condition met this cycle: the state machine takes the safe state next cycle.
  void raise(FirmwareFault fault);
  // The machine's own signals (PLANT_EMERGENCY, SENS_MACHINE's PlantFaults and PlantState, the plant
  // heartbeat's state): raised as faults with their names (docs/safety.md, H6).
  void check_plant_signals(bool complete);
  // Takes the SUPERVISOR commands the port received: acknowledge, start, and stop (raised as
  // FirmwareFault::operator_stop once the node commands the machine).
  void take_supervisor_commands();
  // The stop along the path (control/path_stop.hpp) from loop time t, and the path time at t.
  void begin_path_stop(double t);
  bool path_stop_moving(double t) const;  // a stop along the path is slowing the path at loop time t
  double path_time_at(double t, double& rate, double& rate_dot) const;
  double path_time_at(double t) const {
    double rate = 1, rate_dot = 0;
    return path_time_at(t, rate, rate_dot);
  }
  double unslowed_task_time(double t) const { return t - track_start_ + task_.start_time(); }
  // The velocity plausibility monitor on this cycle's valve command (valve interface).
  void check_plausibility(bool restarted);
  // What the flow plausibility monitor measures: positions, the oil columns' compression F / K_h
  // (zero without pressures) and the functions at a relief.
  struct FlowMeasurement {
    Vec4 position = Vec4::Zero(), compression = Vec4::Zero();
    std::uint8_t at_relief = 0;
  };
  FlowMeasurement flow_measurement() const;
  // The chamber pressures' plausibility monitor on this cycle's sensor set (valve interface, H4).
  void check_pressures(bool restarted);
  // Sends FW_EMERGENCY for the current safe state: EmergencyStop set when its fault takes the
  // emergency stop.
  void send_stop_frame();
  // The standstill monitor of a controlled stop (docs/safety.md, H1/H2).
  void check_standstill(bool complete);

  const Model& model_;
  ActuatorFriction friction_;  // the nominal machine's (start-up)
  const control::Task& task_;
  FirmwareNodeConfig config_;
  hal::FirmwareCanPort& port_;
  telemetry::TelemetryPublisher* telemetry_;
  std::unique_ptr<control::Controller> controller_;
  std::int8_t controller_id_;  // the law's number in telemetry (ControllerRegistry::id_of)
  control::StateEstimator estimator_;
  control::ControlStateMachine machine_;
  control::CommandBlender blender_;
  control::ActuatorLagCompensator lag_compensator_;
  control::ValveInnerLoop valves_;
  control::PumpPacing pacing_;    // the path's clock when paced to the pumps (controller.pump_pacing)
  control::VelocityPlausibility plausibility_;
  control::FrozenPosition frozen_position_;  // the reading that stops while its function is driven
  control::PressurePlausibility pressure_monitor_;
  std::uint64_t pump_limited_cycles_ = 0;
  bool pump_warning_ = false;
  int pump_run_ = 0;  // cycles in a row the pumps' state has differed from the warning's
  double pump_warning_start_ = 0, pump_warning_peak_ = 0;
  std::uint64_t pump_warnings_ = 0;
  char warning_text_[160] = "";
  control::PerfCounter control_timing_;
  control::PerfCounter cycle_timing_;
  control::PerfCounter read_timing_, write_timing_, telemetry_timing_, interval_timing_;
  std::uint64_t deadline_overruns_ = 0, skipped_deadlines_ = 0;
  BusLoadWindow bus_load_;

  double period_;
  std::uint64_t cycle_ = 0;
  bool have_valid_ = false;
  bool complete_ = false;
  control::Transition transition_;
  TrackingMetrics measured_;
  double last_valid_time_ = -1e300;
  double track_start_ = 0;
  double path_time_ = 0;          // the task time tracked this cycle (slowed by a stop along the path)
  control::PathStop path_stop_;
  double path_stop_start_ = 0;    // s, loop time the stop along the path began
  bool operator_stop_on_rest_ = false;  // the SUPERVISOR stop latches once the path has come to rest
  double operator_stop_time_ = 0;       // s, the cycle its frame arrived
  Vec4 held_q_ = Vec4::Zero();
  Vec4 q_d_ = Vec4::Zero(), qd_d_ = Vec4::Zero(), qdd_d_ = Vec4::Zero();
  Vec4 last_sent_ = Vec4::Zero();
  bool fault_ = false;
  FirmwareFault pending_fault_ = FirmwareFault::none;  // raised by this cycle's computation
  FirmwareFault fault_code_ = FirmwareFault::none;     // of the last safe stop
  char pending_text_[160] = "";
  double pending_time_ = 0;           // s, the cycle the pending fault was raised
  double fault_detected_time_ = -1;   // s, of the last safe stop's fault
  char fault_text_[160] = "";
  bool finished_ = false;
  double finish_time_ = 0;
  bool stop_requested_ = false;
  bool acknowledge_requested_ = false;
  bool start_received_ = false;
  bool operator_stop_pending_ = false;  // a SUPERVISOR stop not yet raised (the node did not command yet)
  bool link_armed_ = false;       // a keep-alive was heard: the operator link is monitored
  bool link_lost_ = false;        // silent past supervisor_timeout since the last frame
  bool link_stop_ = false;        // the stop under way is the lost link's, not the station's own
  double last_supervisor_time_ = 0;  // s, the cycle the last SUPERVISOR frame was taken
  bool emergency_sent_ = false;
  bool safe_command_sent_ = false;
  bool escalated_ = false;  // the controlled stop became an emergency stop (standstill monitor)
  CreepWindow cylinder_creep_;  // the standstill's creep test on the cylinders' oil taken (kStandstillWindow)
  CreepWindow swing_creep_;     // and on the swing's motion (kStandstillSwingWindow)
  int plant_hold_run_ = 0;        // consecutive sensor sets saying the plant holds while commanded
  int missed_in_a_row_ = 0;
  std::uint64_t safe_stops_ = 0;
  std::uint64_t safe_stop_cycle_ = 0;  // cycle the last safe state began
  hal::SensorState sensors_;
  hal::CommandState command_;
  control::ControlOutput out_;
};

}  // namespace exc::app
