#pragma once
// The firmware's fault kinds and the stop each one takes (docs/safety.md, "The two stops"). The
// codes travel in FW_EMERGENCY's FaultCode and in fault_t.code.
#include <cstdint>

namespace exc::safety {

enum class FirmwareFault : std::uint16_t {
  none = 0,
  sensor_timeout = 1,  // watchdog: no valid sensor set within the timeout
  model = 2,           // the closed-chain model refused the state (no assembly, toggle)
  tracking_error = 3,  // a joint's |q_a - q_d| exceeded controller.tracking_error_limit
  no_pressures = 4,    // the valve stage's force loop needs chamber pressures the sensor frame lacks
  // A warning (EXC_FAULT severity 1, no safe stop): the valves ask the pumps for more than their flow
  // for kPumpWarningCycles in a row, so every function slows; cleared after as many within it.
  pump_limited = 5,
  plant_emergency = 6,     // PLANT_EMERGENCY received: the machine stopped on its own
  plant_fault = 7,         // SENS_MACHINE's PlantFaults non-zero: the machine reports a failure
  plant_holding = 8,       // the machine says it holds (PlantState) while the firmware commands motion
  deadline_overrun = 9,    // real time: controller.max_missed_deadlines wake-ups in a row after their deadline
  velocity_implausible = 10,  // a function moves unlike its valve's command (stuck or runaway spool)
  exited = 11,         // the program leaves (end of run, a signal): its last command centres the valves
  fatal_error = 12,    // the program leaves on an error: the same, with the emergency stop
  operator_stop = 13,  // an operator's stop (SUPERVISOR Command = stop): latched until acknowledged
  pressure_implausible = 14,  // a chamber pressure out of range, jumping or stuck (pressure_plausibility.hpp)
  // The operator station's link fell silent: it had sent keep-alives (SUPERVISOR Command = none),
  // then nothing for controller.supervisor_timeout. Stops as an operator's stop does, latched.
  operator_link_lost = 15,
  // A main-valve spool's measured position disagrees with the one its command leads to: further
  // from neutral, the other way, or off neutral with neutral commanded (spool_monitor.hpp).
  spool_disagreement = 16,
};

// The stop a fault takes. controlled: valves centred, EmergencyStop = 0 (the valves still obey).
// emergency: EmergencyStop = 1 as well, so the machine cuts the pilot supply and stops the engine
// (the valves or the sensors cannot be trusted). none: a warning, no stop.
enum class StopKind : std::uint8_t { none, controlled, emergency };

constexpr StopKind stop_of(FirmwareFault fault) {
  switch (fault) {
    case FirmwareFault::none:
    case FirmwareFault::pump_limited: return StopKind::none;
    case FirmwareFault::model:
    case FirmwareFault::tracking_error:
    case FirmwareFault::no_pressures:
    case FirmwareFault::deadline_overrun:
    // The valves still obey and centring them needs no pressure; the position sensors, which the
    // standstill monitor watches, are not in doubt (docs/safety.md, H4).
    case FirmwareFault::pressure_implausible:
    case FirmwareFault::exited:
    case FirmwareFault::operator_stop:
    case FirmwareFault::operator_link_lost: return StopKind::controlled;
    case FirmwareFault::sensor_timeout:
    case FirmwareFault::plant_emergency:
    case FirmwareFault::plant_fault:
    case FirmwareFault::plant_holding:
    case FirmwareFault::velocity_implausible:
    case FirmwareFault::spool_disagreement:
    case FirmwareFault::fatal_error: return StopKind::emergency;
  }
  return StopKind::emergency;  // an unknown code: the stronger stop
}

// A controlled stop that first decelerates the machine along its path (control/task/path_stop.hpp) and
// latches once the path is at rest: only where the law, its sensors and the path are all sound. An
// operator's stop (or a lost operator link) is; a tracking error, a refused model state, a late or pressure-blind loop are not,
// and their stop centres the valves at once.
constexpr bool stops_along_path(FirmwareFault fault) {
  return fault == FirmwareFault::operator_stop || fault == FirmwareFault::operator_link_lost;
}

// The standstill monitor of a controlled stop (IEC 60204-1 category 1: a controlled stop, then the
// power removed if the machine does not stand still). Two tests escalate the stop to the emergency
// stop. First, on the valve interface, the flow plausibility monitor keeps running against centred
// valves: oil arriving that was not asked for (motion plus compression) is a valve that does not
// close, found as fast as in tracking (it runs whether or not the tracking fault is enabled); a
// boom ringing on its oil column or a swing braking on its reliefs moves no oil through a valve and
// does not trip it. Second, for any interface, from kStandstillDelay after the safe state began, a
// cylinder whose mean velocity (with pressures, of its motion plus its oil's compression) over a
// kStandstillWindow exceeds its standstill rate and has not fallen by kStandstillSlowing against
// the window before: a creep below the flow test's floor (ringing averages out; a function braking
// slows from window to window). The rate is twice the campaign's "at rest" (1 mm/s). The swing's
// motor leaks across its ports (5 % of its flow at relief), so its oil's compression does not hold
// still: its creep test is on its motion alone, over windows as long as its oil spring's period
// (kStandstillSwingWindow, about 2.5 s on the reference machine), which its ringing averages out of.
inline constexpr double kStandstillDelay = 0.3;            // s
inline constexpr double kStandstillSlowing = 0.2;          // share the mean speed must fall per window
inline constexpr double kStandstillWindow = 0.5;           // s
inline constexpr double kStandstillCylinderRate = 0.002;  // m/s
inline constexpr double kStandstillSwingWindow = 2.5;      // s
inline constexpr double kStandstillSwingRate = 0.002;     // rad/s
// A mean this many times the rate over a whole window, going one way through it, escalates whether or
// not it fell against the window before (CreepWindow): 20 mm/s over 0.5 s, 20 mrad/s over 2.5 s, well
// after any braking; a ring turns within the window.
inline constexpr double kStandstillFastFactor = 10;

const char* to_string(FirmwareFault fault);
const char* to_string(StopKind stop);

}  // namespace exc::safety
