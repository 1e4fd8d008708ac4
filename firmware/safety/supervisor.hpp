#pragma once
// Supervision of the firmware's cycle (PX4's failsafe beside its commander): every monitor, the
// latched fault and its text, the stop's escalation, the operator link and the machine's own
// signals. A pure library: the node feeds it each cycle's inputs in the order it learns them and
// takes back the state machine's inputs (fault, acknowledged), the stop frames to send and the fault
// events to publish. It sees no bus and no clock; nothing here allocates, locks or blocks.
//
// One cycle, as FirmwareNode::end_cycle calls it:
//   take_operator()        acknowledge, start, the operator's stop and link (may ask for a stop along
//                          the path, which the node begins)
//   take_signals()         an operator stop latches once the path is at rest; the machine's signals
//   state_inputs()         -> the state machine; on_transition() latches or releases the stop
//   check_standstill()     a controlled stop that does not come to rest escalates (safe_stop only)
//   check_law(), check_pressures(), require_pressures(), check_flow(), update_pump_warning()
//                          the tracking cycle's monitors (hold and track)
//   next_event()           the fault events raised this cycle, for telemetry
#include <cstdint>

#include "hal/excavator_interface.hpp"
#include "model/machine.hpp"
#include "model/types.hpp"
#include "safety/creep_window.hpp"
#include "safety/firmware_faults.hpp"
#include "safety/frozen_position.hpp"
#include "safety/pressure_plausibility.hpp"
#include "safety/spool_monitor.hpp"
#include "safety/state_machine.hpp"
#include "safety/velocity_plausibility.hpp"

namespace exc::safety {

// The supervisor's own settings (ControllerConfig's `supervisor` member: controller.supervisor_timeout,
// max_missed_deadlines, tracking_error_limit and the monitors' sections); it takes the period beside
// them.
struct SupervisorSettings {
  // s without a SUPERVISOR frame, once the operator station has sent a keep-alive (Command none),
  // that stops the machine as the station's stop would (FirmwareFault::operator_link_lost): five
  // of excavator-operator keep-alive's 0.1 s frames missed. 0: the link is not monitored.
  double supervisor_timeout = 0.5;
  // Real time: this many wake-ups in a row after their deadline are a fault (docs/safety.md, H7):
  // one late cycle costs a cycle of latency, five in a row is a loop that lost its period.
  int max_missed_deadlines = 5;
  // |q_a - q_d| per joint above which the firmware faults to its safe state (hold and track): a
  // machine far from where it was told to go must stop; rad (swing), m (cylinders). On the valve
  // interface derive_defaults sets kTrackingLimitMultiple x what the valve machine reaches
  // (control/controller_config.hpp); on the effort interface (the paper's force actuators, whose PID
  // baseline errs up to 0.12 m on the bucket in its dig) about twice that baseline's worst, 0.5-1 m at
  // the tip.
  Vec4 tracking_error_limit = (Vec4() << 0.1, 0.2, 0.2, 0.2).finished();
  // Commanded against measured velocity per function on the valve interface (docs/safety.md, H1).
  // Its floors default to shares of each function's top speed and effort (derive_defaults).
  PlausibilitySettings plausibility;
  // The chamber pressures' range, steps and stuck-at readings on the valve interface (docs/safety.md,
  // H4); its limits come from the machine file's hydraulics section (pressure_plausibility.hpp).
  PressurePlausibilitySettings pressure_plausibility;
  // Each measured spool against its command through the valve's lag, valve interface (spool_monitor.hpp;
  // docs/safety.md, H1).
  SpoolMonitorSettings spool_monitor;
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, SupervisorSettings& s) {
  v("supervisor_timeout", s.supervisor_timeout);
  v("max_missed_deadlines", s.max_missed_deadlines);
  v("tracking_error_limit", s.tracking_error_limit);
  v("plausibility", s.plausibility);
  v("pressure_plausibility", s.pressure_plausibility);
  v("spool_monitor", s.spool_monitor);
}

// What the flow plausibility monitor measures: positions, the oil columns' compression F / K_h
// (zero without pressures) and the functions at a relief (bit j).
struct FlowMeasurement {
  Vec4 position = Vec4::Zero(), compression = Vec4::Zero();
  std::uint8_t at_relief = 0;
};

// A fault raised or cleared, as EXC_FAULT carries it.
struct FaultEvent {
  FirmwareFault code = FirmwareFault::none;
  std::int8_t severity = 0;  // 1 warning, 2 stops the controller
  bool active = false;
  char text[160] = "";
};

// The FW_EMERGENCY frame to send: EmergencyStop and FaultCode.
struct StopFrame {
  bool emergency = false;
  FirmwareFault code = FirmwareFault::none;
};

// What the node knows when it reads the cycle's bus.
struct CycleInputs {
  double t = 0;             // s, the loop's time
  std::uint64_t cycle = 0;
  bool complete = false;    // this cycle's sensor set arrived
  Mode mode = Mode::init;   // the mode before this cycle's transition
};

inline constexpr int kPumpWarningCycles = 20;
// Sensor sets in a row that say the plant holds while the firmware commands motion before that is a
// fault: the plant applies a command one cycle after it is sent, so a hold it reports on entering
// hold/track lasts one or two sets; five is a machine that does not obey.
inline constexpr int kPlantHoldCycles = 5;

class Supervisor {
 public:
  Supervisor(const Machine& nominal, const SupervisorSettings& settings, double period);

  // An operator acknowledges the latched stop (on the operator's behalf: a caller, not a frame):
  // taken on the next cycle, as a SUPERVISOR acknowledge is.
  void acknowledge() { acknowledge_requested_ = true; }

  // The SUPERVISOR commands received (sensors.supervisor_pending, which the caller then clears):
  // acknowledge, start, stop, the operator link's keep-alive. Returns true when a stop along the
  // path must begin now (an operator's stop reaching a tracking machine whose path is not yet
  // slowing: path_stopping).
  bool take_operator(const CycleInputs& in, std::uint8_t supervisor_pending, bool path_stopping);
  // After any stop along the path began: an operator's stop latches once the path is at rest
  // (path_moving false); then the machine's own signals (PLANT_EMERGENCY, taken once per frame: the
  // caller clears sensors.plant_emergency; PlantFaults; PlantState holding while commanded).
  void take_signals(const CycleInputs& in, const hal::SensorState& sensors, bool path_moving);

  // The state machine's inputs the supervisor owns.
  bool fault_pending() const { return fault_; }
  bool acknowledged() const { return acknowledged_; }

  // The state machine's transition this cycle. Entering the safe state latches the pending fault
  // (or the watchdog's sensor timeout): its FW_EMERGENCY goes out now (send_stop). Entering hold
  // clears the fault; from the safe state it releases the machine's latch (release: FW_EMERGENCY
  // with EmergencyStop = 0 and no fault, so the machine obeys again).
  enum class StopAction : std::uint8_t { none, send_stop, release };
  StopAction on_transition(const Transition& transition, const CycleInputs& in, double last_valid_time);

  // The standstill monitor of a controlled stop, in the safe state (mode: after this cycle's
  // transition): the flow test against centred valves (valves_measured: valve interface with
  // pressures) and the creep tests from kStandstillDelay on. `complete`: this cycle's sensor set
  // arrived. Returns true when the stop escalates now (its FW_EMERGENCY goes out).
  bool check_standstill(Mode mode, std::uint64_t cycle, bool complete, const FlowMeasurement& m, bool valves_measured);

  // The law's output: a model it could not evaluate (or a non-finite effort), and the tracking-error
  // limit (task_start: the first cycle of the task, the machine not yet where the path begins).
  void check_law(double t, bool model_ok, const Vec4& e, bool task_start);
  // The chamber pressures' plausibility (valve interface; active: pressures valid, no restart).
  void check_pressures(double t, bool active, bool fresh, const hal::SensorState& sensors);
  void idle_pressures();  // not commanding: the pressure monitor restarts
  // The valve stage's force loop needs the pressures: a set without them is a fault.
  void require_pressures(double t, bool valid);
  // The flow plausibility monitor and the frozen-position test on this cycle's valve command
  // (expected velocity) against what arrived (valve interface; active: no restart).
  void check_flow(double t, bool active, const Vec4& expected_velocity, const FlowMeasurement& m, const Vec4& velocity);
  // The spool monitor: this cycle's measured spools against the expected ones (active: valve
  // interface with spools measured, commanding, the set complete), then the spool targets just sent
  // (every cycle; centred valves: zeros), which the next set is expected to follow.
  void check_spools(double t, bool active, const Vec4& measured);
  void command_spools(const Vec4& target) { spool_monitor_.command(target); }
  void restart_spools() { spool_monitor_.reset(); }
  // The pump-limited warning's debounce, raise and clear (FirmwareFault::pump_limited).
  void update_pump_warning(double t, bool limited, double demanded_flow);
  // A real-time loop's wake-up: kept deadlines or not; max_missed_deadlines in a row while
  // commanding is a fault (detected at next_cycle_time, the cycle about to start).
  void record_wakeup(std::uint64_t overruns, std::uint64_t skipped, Mode mode, double next_cycle_time);

  // FW_EMERGENCY: the stop frame of the standing safe state; the exit's frame (valves centred, the
  // program leaving for `why`; a standing safe state keeps its own fault). Both note an emergency sent.
  StopFrame stop_frame();
  StopFrame exit_frame(FirmwareFault why, Mode mode);
  // FW_EMERGENCY repeats every kEmergencyRepeatCycles while the safe state lasts.
  bool stop_frame_due(std::uint64_t cycle, Mode mode, int repeat_cycles) const {
    return mode == Mode::safe_stop && cycle > safe_stop_cycle_ && (cycle - safe_stop_cycle_) % static_cast<std::uint64_t>(repeat_cycles) == 0;
  }

  // The fault events raised this cycle, oldest first; false when none is left.
  bool next_event(FaultEvent& event);

  // The fault of the last safe stop (none before any), its text and when it was detected (s; -1
  // before any): the cycle its condition was first met, or for a sensor timeout the first cycle
  // without a valid sensor set.
  FirmwareFault last_fault() const { return fault_code_; }
  const char* last_fault_text() const { return fault_text_; }
  double fault_detected_time() const { return fault_detected_time_; }
  std::uint64_t safe_stops() const { return safe_stops_; }
  // The stop the last safe state took: a controlled stop escalates to the emergency stop when the
  // machine does not stand still with its valves centred.
  StopKind last_stop() const { return escalated_ ? StopKind::emergency : stop_of(fault_code_); }
  bool stop_escalated() const { return escalated_; }
  bool emergency_sent() const { return emergency_sent_; }  // any FW_EMERGENCY with EmergencyStop = 1
  bool start_received() const { return start_received_; }  // an operator's start (SUPERVISOR start)
  std::uint64_t pump_limited_cycles() const { return pump_limited_cycles_; }
  std::uint64_t pump_warnings() const { return pump_warnings_; }
  const char* last_warning_text() const { return warning_text_; }
  int missed_deadlines_in_a_row() const { return missed_in_a_row_; }
  const VelocityPlausibility& plausibility() const { return plausibility_; }
  const FrozenPosition& frozen_position() const { return frozen_position_; }
  const PressurePlausibility& pressure_plausibility() const { return pressure_monitor_; }
  const SpoolMonitor& spool_monitor() const { return spool_monitor_; }
  const SupervisorSettings& settings() const { return s_; }

 private:
  // A fault condition met this cycle (the first one counts): the safe state follows next cycle.
  // Returns the pending text to write, or nullptr when a fault is already pending.
  char* raise(FirmwareFault fault, double t);
  FaultEvent& push_event(FirmwareFault code, std::int8_t severity, bool active);

  SupervisorSettings s_;
  double period_;  // s, the cycle
  double pump_flow_;  // m^3/s, the nominal machine's pumps (the warning's text)
  VelocityPlausibility plausibility_;
  FrozenPosition frozen_position_;  // the reading that stops while its function is driven
  PressurePlausibility pressure_monitor_;
  SpoolMonitor spool_monitor_;
  CreepWindow cylinder_creep_;  // the standstill's creep test on the cylinders' oil taken
  CreepWindow swing_creep_;     // and on the swing's motion

  // The pending fault (raised this cycle or before, not yet in the safe state) and the latched one.
  bool fault_ = false;
  FirmwareFault pending_fault_ = FirmwareFault::none;
  char pending_text_[160] = "";
  double pending_time_ = 0;
  FirmwareFault fault_code_ = FirmwareFault::none;
  char fault_text_[160] = "";
  double fault_detected_time_ = -1;
  std::uint64_t safe_stops_ = 0;
  std::uint64_t safe_stop_cycle_ = 0;
  bool escalated_ = false;
  bool emergency_sent_ = false;

  bool acknowledge_requested_ = false, acknowledged_ = false;
  bool start_received_ = false;
  bool operator_stop_pending_ = false;  // a SUPERVISOR stop not yet taken (the node did not command yet)
  bool operator_stop_on_rest_ = false;  // taken: latches once the path has come to rest
  double operator_stop_time_ = 0;       // s, the cycle its frame arrived (or the link was lost)
  bool link_armed_ = false;  // a keep-alive was heard: the operator link is monitored
  bool link_lost_ = false;   // silent past supervisor_timeout since the last frame
  bool link_stop_ = false;   // the stop under way is the lost link's, not the station's own
  double last_supervisor_time_ = 0;
  int plant_hold_run_ = 0;   // consecutive sensor sets saying the plant holds while commanded

  bool pump_warning_ = false;
  int pump_run_ = 0;  // cycles in a row the pumps' state has differed from the warning's
  double pump_warning_start_ = 0, pump_warning_peak_ = 0;
  std::uint64_t pump_warnings_ = 0, pump_limited_cycles_ = 0;
  char warning_text_[160] = "";

  std::uint64_t deadline_overruns_ = 0, skipped_deadlines_ = 0;
  int missed_in_a_row_ = 0;

  static constexpr int kEvents = 4;
  FaultEvent events_[kEvents];
  int event_count_ = 0, event_next_ = 0;
};

}  // namespace exc::safety
