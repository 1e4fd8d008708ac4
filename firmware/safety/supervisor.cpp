#include "safety/supervisor.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>

namespace exc::safety {
namespace {

// SensorState::supervisor_pending's bit of a command.
std::uint8_t supervisor_bit(hal::SupervisorCommand c) { return static_cast<std::uint8_t>(1u << static_cast<unsigned>(c)); }

Vec4 to_vec(const std::array<double, 4>& a) { return Vec4(a[0], a[1], a[2], a[3]); }

const char* name_of(int j) { return kActiveNames[static_cast<std::size_t>(j)]; }
const char* unit_of(int j) { return j == 0 ? "rad" : "m"; }

bool commanding(Mode mode) { return mode == Mode::hold || mode == Mode::track; }

}  // namespace

Supervisor::Supervisor(const Machine& nominal, const SupervisorSettings& settings, double period)
    : s_(settings),
      period_(period),
      pump_flow_(nominal.hydraulics.pump_flow),
      plausibility_(settings.plausibility, period),
      frozen_position_(settings.plausibility),
      pressure_monitor_(nominal, settings.pressure_plausibility, period),
      spool_monitor_(settings.spool_monitor, nominal.hydraulics.valve_time_constant, period) {}

char* Supervisor::raise(FirmwareFault fault, double t) {
  if (fault_) return nullptr;
  fault_ = true;
  pending_fault_ = fault;
  pending_time_ = t;
  return pending_text_;
}

FaultEvent& Supervisor::push_event(FirmwareFault code, std::int8_t severity, bool active) {
  // Drained every cycle; a cycle raises at most an escalation and a pump warning.
  FaultEvent& e = events_[event_count_ < kEvents ? event_count_++ : kEvents - 1];
  e.code = code;
  e.severity = severity;
  e.active = active;
  return e;
}

bool Supervisor::next_event(FaultEvent& event) {
  if (event_next_ >= event_count_) {
    event_next_ = event_count_ = 0;
    return false;
  }
  event = events_[event_next_++];
  return true;
}

bool Supervisor::take_operator(const CycleInputs& in, std::uint8_t pending, bool path_stopping) {
  // An acknowledge is spent on this cycle: it clears the latched faults of the safe state, and the
  // monitors that watch standing conditions (the plant's signals, the watchdog) raise again if
  // theirs still stands. A stop in the same cycle is raised after it, so it stands.
  if ((pending & supervisor_bit(hal::SupervisorCommand::acknowledge)) != 0) acknowledge_requested_ = true;
  acknowledged_ = acknowledge_requested_ && in.mode == Mode::safe_stop &&
                  (pending & supervisor_bit(hal::SupervisorCommand::stop)) == 0;
  acknowledge_requested_ = false;
  if (acknowledged_) {
    fault_ = false;
    pending_fault_ = FirmwareFault::none;
  }

  if ((pending & supervisor_bit(hal::SupervisorCommand::start)) != 0) start_received_ = true;
  // The operator link: armed by the station's first keep-alive, lost after supervisor_timeout
  // without any frame (ISO 15817's remote control: losing the link stops the machine). Taken as the
  // station's stop; heard again, a later loss is a new one.
  if ((pending & supervisor_bit(hal::SupervisorCommand::none)) != 0) link_armed_ = true;
  if (pending != 0) {
    last_supervisor_time_ = in.t;
    link_lost_ = false;
  }
  const double timeout = s_.supervisor_timeout;
  const bool lost_now = link_armed_ && !link_lost_ && timeout > 0 && in.t - last_supervisor_time_ > timeout;
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
  bool begin_path_stop = false;
  if (in.mode == Mode::safe_stop && !stop_now) {
    operator_stop_pending_ = false;  // stopped already: the stop has latched
  } else if (operator_stop_pending_ && commanding(in.mode) && !fault_) {
    // Not yet commanding (start-up): taken on the first cycle the node commands the machine. A
    // tracking machine first decelerates along its path; the stop latches once the path is at rest.
    operator_stop_pending_ = false;
    if (!operator_stop_on_rest_) operator_stop_time_ = in.t;
    operator_stop_on_rest_ = true;
    begin_path_stop = in.mode == Mode::track && !path_stopping;
  }
  return begin_path_stop;
}

void Supervisor::take_signals(const CycleInputs& in, const hal::SensorState& sensors, bool path_moving) {
  if (operator_stop_on_rest_ && !path_moving && !fault_) {
    operator_stop_on_rest_ = false;
    char* text = raise(link_stop_ ? FirmwareFault::operator_link_lost : FirmwareFault::operator_stop, in.t);
    pending_time_ = operator_stop_time_;  // detected when its frame came (or failed to), whatever the deceleration took
    if (link_stop_) {
      link_stop_ = false;
      std::snprintf(text, sizeof pending_text_,
                    "operator link lost: no SUPERVISOR frame for %.3f s (the last at t = %.3f s), in %s; the path at rest "
                    "%.3f s later",
                    s_.supervisor_timeout, last_supervisor_time_, to_string(in.mode), in.t - operator_stop_time_);
    } else {
      std::snprintf(text, sizeof pending_text_, "operator stop: SUPERVISOR stop in %s at t = %.3f s, the path at rest %.3f s later",
                    to_string(in.mode), operator_stop_time_, in.t - operator_stop_time_);
    }
  }
  // PLANT_EMERGENCY is an event the plant repeats every 10 ms while it lasts: taken once per frame.
  if (sensors.plant_emergency) {
    if (char* text = raise(FirmwareFault::plant_emergency, in.t))
      std::snprintf(text, sizeof pending_text_, "plant emergency: PLANT_EMERGENCY code %u, plant heartbeat state %u, at t = %.3f s",
                    static_cast<unsigned>(sensors.plant_fault_code), static_cast<unsigned>(sensors.plant_heartbeat_state), in.t);
  }
  if (!in.complete) return;
  if (sensors.plant_faults != 0) {
    if (char* text = raise(FirmwareFault::plant_fault, in.t))
      std::snprintf(text, sizeof pending_text_, "plant fault: SENS_MACHINE PlantFaults 0x%02x at t = %.3f s",
                    static_cast<unsigned>(sensors.plant_faults), in.t);
  }
  plant_hold_run_ = commanding(in.mode) && (sensors.plant_state & hal::kPlantStateHolding) != 0 ? plant_hold_run_ + 1 : 0;
  if (plant_hold_run_ >= kPlantHoldCycles) {
    if (char* text = raise(FirmwareFault::plant_holding, in.t))
      std::snprintf(text, sizeof pending_text_,
                    "plant holding: PlantState %u for %d sensor sets while commanded (heartbeat state %u) at t = %.3f s",
                    static_cast<unsigned>(sensors.plant_state), plant_hold_run_,
                    static_cast<unsigned>(sensors.plant_heartbeat_state), in.t);
  }
}

Supervisor::StopAction Supervisor::on_transition(const Transition& transition, const CycleInputs& in, double last_valid_time) {
  if (!transition.changed) return StopAction::none;
  if (transition.to == Mode::hold) {
    fault_ = false;
    pending_fault_ = FirmwareFault::none;
    escalated_ = false;
    return transition.from == Mode::safe_stop ? StopAction::release : StopAction::none;
  }
  if (transition.to != Mode::safe_stop) return StopAction::none;
  operator_stop_on_rest_ = false;  // whatever stopped the machine, an operator's stop under way is in it
  ++safe_stops_;
  safe_stop_cycle_ = in.cycle;
  fault_code_ = fault_ ? pending_fault_ : FirmwareFault::sensor_timeout;
  // A sensor timeout is detected from the first cycle of the gap that ended in it.
  fault_detected_time_ = fault_ ? pending_time_ : last_valid_time + period_;
  if (fault_code_ == FirmwareFault::sensor_timeout)
    std::snprintf(fault_text_, sizeof fault_text_, "sensor timeout: no valid sensor set for %.0f ms at t = %.3f s",
                  (in.t - last_valid_time) * 1e3, in.t);
  else
    std::memcpy(fault_text_, pending_text_, sizeof fault_text_);
  return StopAction::send_stop;
}

bool Supervisor::check_standstill(Mode mode, std::uint64_t cycle, bool complete, const FlowMeasurement& m, bool valves_measured) {
  if (mode != Mode::safe_stop) return false;  // tracking: check_flow runs the monitor
  if (escalated_ || stop_of(fault_code_) != StopKind::controlled || !complete) {
    plausibility_.update(false);
    cylinder_creep_.restart();
    swing_creep_.restart();
    return false;
  }
  char why[120] = "";
  if (valves_measured) {
    // The valves are centred: every bit of oil that arrives is unasked for.
    plausibility_.update(true, Vec4::Zero(), m.position, m.compression, m.at_relief);
    const std::uint8_t found = plausibility_.implausible();
    for (int j = 0; j < 4 && why[0] == 0; ++j)
      if ((found >> j) & 1)
        std::snprintf(why, sizeof why, "%s took %.4f %s with its valve centred", name_of(j), plausibility_.delivered()[j], unit_of(j));
  } else {
    plausibility_.update(false);
  }
  const double since = static_cast<double>(cycle - safe_stop_cycle_) * period_;
  if (why[0] == 0 && since >= kStandstillDelay) {
    constexpr double kOut = std::numeric_limits<double>::infinity();
    // The cylinders on the oil they took: motion plus, with pressures, compression (a load that
    // changes, as a braking swing's pull on the front, moves a held cylinder as much as it
    // compresses its oil; no oil arrives). Not the swing: its motor's cross-port leakage moves a
    // swing trapped on its oil spring for seconds.
    const std::uint8_t cylinders = cylinder_creep_.update(
        m.position + m.compression, cycle, period_, kStandstillWindow,
        Vec4(kOut, kStandstillCylinderRate, kStandstillCylinderRate, kStandstillCylinderRate), kStandstillSlowing, kStandstillFastFactor);
    // The swing on its motion alone, over windows as long as its oil spring's period, which its
    // ringing averages out of: a spool stuck just past its dead zone creeps on, not slowing.
    const std::uint8_t swing = swing_creep_.update(m.position, cycle, period_, kStandstillSwingWindow,
                                                   Vec4(kStandstillSwingRate, kOut, kOut, kOut), kStandstillSlowing, kStandstillFastFactor);
    for (int j = 1; j < 4 && why[0] == 0; ++j)
      if ((cylinders >> j) & 1)
        std::snprintf(why, sizeof why, "%s takes %.4f m/s on average over %.1f s, not stopping", name_of(j), cylinder_creep_.mean()[j],
                      cylinder_creep_.window());
    if (why[0] == 0 && (swing & 1))
      std::snprintf(why, sizeof why, "swing moves %.4f rad/s on average over %.1f s, not stopping", swing_creep_.mean()[0],
                    swing_creep_.window());
  }
  if (why[0] == 0) return false;
  escalated_ = true;
  FaultEvent& e = push_event(fault_code_, 2, true);
  // A longer text is cut at the event's (fault_t's) field.
  if (std::snprintf(e.text, sizeof e.text, "controlled stop escalated to the emergency stop %.2f s after it: %s (%s)", since, why,
                    fault_text_) < 0)
    e.text[0] = 0;
  return true;
}

void Supervisor::check_law(double t, bool model_ok, const Vec4& e, bool task_start) {
  if (!model_ok) {
    if (char* text = raise(FirmwareFault::model, t))
      std::snprintf(text, sizeof pending_text_, "model: the closed-chain model refused the state at t = %.3f s", t);
  }
  // Far from where it was told to go: stop (the state machine takes the safe state next cycle). In
  // the first cycle of the task the machine is not standing where the task starts: said as such.
  for (int j = 0; j < 4 && !fault_; ++j) {
    const double limit = s_.tracking_error_limit[j];
    if (std::abs(e[j]) <= limit) continue;
    char* text = raise(FirmwareFault::tracking_error, t);
    if (task_start)
      std::snprintf(text, sizeof pending_text_, "tracking error at the task's start: %s %.4f %s from its first point > limit %.4f",
                    name_of(j), std::abs(e[j]), unit_of(j), limit);
    else if (pump_warning_)  // the likely cause, named: a path that asks more than the pumps give lags
      std::snprintf(text, sizeof pending_text_,
                    "tracking error: %s %.4f %s > limit %.4f at t = %.3f s, the pumps short of flow since t = %.3f s", name_of(j),
                    std::abs(e[j]), unit_of(j), limit, t, pump_warning_start_);
    else
      std::snprintf(text, sizeof pending_text_, "tracking error: %s %.4f %s > limit %.4f at t = %.3f s", name_of(j), std::abs(e[j]),
                    unit_of(j), limit, t);
  }
}

void Supervisor::check_pressures(double t, bool active, bool fresh, const hal::SensorState& sensors) {
  const Vec4 p_a = to_vec(sensors.pressure_a), p_b = to_vec(sensors.pressure_b);
  const std::uint8_t found = pressure_monitor_.update(active, fresh, p_a, p_b, to_vec(sensors.position), to_vec(sensors.velocity));
  if (found == 0 || fault_) return;
  int c = 0;
  while (((found >> c) & 1) == 0) ++c;
  char* text = raise(FirmwareFault::pressure_implausible, t);
  const int j = c / 2;
  const double p = (c % 2 == 0 ? p_a : p_b)[j];
  std::snprintf(text, sizeof pending_text_, "pressure implausible at t = %.3f s: %s %s %.2f MPa %s", t, name_of(j), c % 2 == 0 ? "A" : "B",
                p * 1e-6, to_string(pressure_monitor_.test_of(c)));
}

void Supervisor::idle_pressures() { pressure_monitor_.update(false, false, Vec4::Zero(), Vec4::Zero(), Vec4::Zero(), Vec4::Zero()); }

void Supervisor::require_pressures(double t, bool valid) {
  if (valid) return;
  if (char* text = raise(FirmwareFault::no_pressures, t))
    std::snprintf(text, sizeof pending_text_, "no pressures: the valve stage's force loop needs the chamber pressures (t = %.3f s)", t);
}

void Supervisor::check_flow(double t, bool active, const Vec4& expected_velocity, const FlowMeasurement& m, const Vec4& velocity) {
  // The command just computed is what the valves are told from now on; the motion and pressures
  // measured now answer the commands before it, which the monitor's lag stands for.
  const std::uint8_t found = plausibility_.update(active, expected_velocity, m.position, m.compression, m.at_relief);
  const std::uint8_t frozen = frozen_position_.update(active, plausibility_, m.position, m.at_relief);
  const std::uint8_t either = found | frozen;
  if (either == 0 || fault_ || !plausibility_.settings().enabled) return;
  int j = 0;
  while (((either >> j) & 1) == 0) ++j;
  char* text = raise(FirmwareFault::velocity_implausible, t);
  if (((found >> j) & 1) == 0) {
    std::snprintf(text, sizeof pending_text_, "no motion at t = %.3f s: %s read %.5f %s for %d sets while asked %.3f %s/s", t, name_of(j),
                  m.position[j], unit_of(j), frozen_position_.settings().frozen_sets, plausibility_.expected()[j], unit_of(j));
    return;
  }
  // Detected when the debounce is complete: the time a fault's start is judged against.
  std::snprintf(text, sizeof pending_text_,
                "flow implausible at t = %.3f s: %s took %.4f %s over %.2f s, asked %.4f (velocity %.3f, flow asked %.3f)", t, name_of(j),
                plausibility_.delivered()[j], unit_of(j), plausibility_.settings().window, plausibility_.asked()[j], velocity[j],
                plausibility_.expected()[j]);
}

void Supervisor::check_spools(double t, bool active, const Vec4& measured) {
  const int j = spool_monitor_.check(active, measured);
  if (j < 0 || fault_) return;
  char* text = raise(FirmwareFault::spool_disagreement, t);
  std::snprintf(text, sizeof pending_text_, "spool disagreement at t = %.3f s: %s spool at %.3f, expected %.3f (%s) for %d sets", t,
                name_of(j), measured[j], spool_monitor_.expected()[j], to_string(spool_monitor_.failed_test()),
                spool_monitor_.settings().debounce);
}

void Supervisor::update_pump_warning(double t, bool limited, double demanded_flow) {
  if (limited) ++pump_limited_cycles_;
  if (pump_warning_) pump_warning_peak_ = std::max(pump_warning_peak_, demanded_flow);
  pump_run_ = limited != pump_warning_ ? pump_run_ + 1 : 0;
  if (pump_run_ < kPumpWarningCycles) return;
  pump_run_ = 0;
  pump_warning_ = limited;
  if (limited) {
    ++pump_warnings_;
    pump_warning_start_ = t;
    pump_warning_peak_ = demanded_flow;
    std::snprintf(warning_text_, sizeof warning_text_,
                  "pumps short of flow: the valves ask %.0f L/min of their %.0f L/min, every function slows to %.0f %% "
                  "(t = %.3f s)",
                  demanded_flow * 60000, pump_flow_ * 60000, 100 * pump_flow_ / demanded_flow, t);
  } else {
    std::snprintf(warning_text_, sizeof warning_text_,
                  "pumps within their flow again after %.2f s (at most %.0f L/min asked of %.0f; t = %.3f s)", t - pump_warning_start_,
                  pump_warning_peak_ * 60000, pump_flow_ * 60000, t);
  }
  FaultEvent& e = push_event(FirmwareFault::pump_limited, 1, limited);
  std::memcpy(e.text, warning_text_, sizeof e.text);
}

void Supervisor::record_wakeup(std::uint64_t overruns, std::uint64_t skipped, Mode mode, double next_cycle_time) {
  const bool missed = overruns > deadline_overruns_ || skipped > skipped_deadlines_;
  missed_in_a_row_ = missed ? missed_in_a_row_ + 1 : 0;
  deadline_overruns_ = overruns;
  skipped_deadlines_ = skipped;
  if (missed_in_a_row_ < s_.max_missed_deadlines || !commanding(mode)) return;
  if (char* text = raise(FirmwareFault::deadline_overrun, next_cycle_time))
    std::snprintf(text, sizeof pending_text_, "missed deadlines: %d wake-ups in a row after their deadline (limit %d) at t = %.3f s",
                  missed_in_a_row_, s_.max_missed_deadlines, next_cycle_time);
}

StopFrame Supervisor::stop_frame() {
  const bool emergency = escalated_ || stop_of(fault_code_) == StopKind::emergency;
  emergency_sent_ = emergency_sent_ || emergency;
  return StopFrame{emergency, fault_code_};
}

StopFrame Supervisor::exit_frame(FirmwareFault why, Mode mode) {
  // A standing safe state keeps its own fault (and its stop); otherwise the reason of leaving.
  const bool stopped = mode == Mode::safe_stop;
  const FirmwareFault code = stopped ? fault_code_ : why;
  const bool emergency = (stopped && escalated_) || stop_of(code) == StopKind::emergency || stop_of(why) == StopKind::emergency;
  emergency_sent_ = emergency_sent_ || emergency;
  return StopFrame{emergency, code};
}

}  // namespace exc::safety
