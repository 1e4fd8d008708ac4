#pragma once
// The firmware process's cycle on a CAN bus, lockstep or real time (excavator-firmware's loop; the
// in-process harness drives the same FirmwareNode calls with the plant between them). Each cycle
// sends SYNC (begin_cycle), waits for the plant's sensor set until its deadline, computes and sends
// the commands (end_cycle). Lockstep: the next cycle starts as soon as this one is done, so a run is
// deterministic. Real time: cycles wake on absolute deadlines of the period (hal::DeadlineSleeper),
// whose grid starts once the plant has answered, and a sensor wait ends 10 % of a period before the
// next deadline. On every way out the machine is left with a last safe command (valves centred).
#include <atomic>
#include <cstdint>
#include <cstdio>
#include <string>

#include "app/firmware_node.hpp"
#include "app/run_phases.hpp"
#include "hal/can_bus.hpp"

namespace exc::app {

struct RunnerOptions {
  std::int64_t cycles = 0;
  std::int64_t period_ns = 1'000'000;
  bool realtime = false;
  std::int64_t sensor_wait_ns = 250'000'000;       // a cycle's wait for sensors once the plant has answered
  std::int64_t startup_wait_ns = 60'000'000'000;   // the wait until its first answer
  double max_overrun_fraction = 0.01;              // real time: late wake-ups + skipped periods allowed
  double stop_hold_s = 0;  // after a stop request and the deceleration along the path: hold this long, then end
};

// Real time lets the sensor wait run to 10 % of the period before the next deadline: the longest
// wait it can honour (ns).
inline std::int64_t realtime_sensor_wait_limit_ns(std::int64_t period_ns) { return period_ns * 9 / 10; }

struct RunnerOutcome {
  std::uint64_t cycles = 0;
  std::uint64_t overruns = 0, skipped_periods = 0;  // real time only
  bool stop_requested = false;  // a first stop request came (signal, caller)
  bool ok = false;
  std::string failure;  // why not ok, the first cause first
  // The run's errors per phase on the firmware's sensed positions (app/run_phases.hpp, the split
  // excavator-sim's summary makes on the plant's truth); a hold that left its pose by more than the
  // holding tolerance once settled fails the run.
  PhaseErrors tracking, settle, hold, stop;
};

// Runs the cycle until options.cycles are done or stop_requests says so: at 1 a tracking machine
// decelerates along its path, holds for stop_hold_s and the run ends (any other mode ends at once), at 2 the run
// ends now. Mode changes are written to progress (may be null). Returns the verdict: a run that
// never tracked, went to its safe state, left a held pose by more than the holding tolerance or
// (real time) missed more deadlines than allowed failed.
RunnerOutcome run_firmware(FirmwareNode& node, hal::CanBus& bus, const RunnerOptions& options,
                           const std::atomic<int>& stop_requests, std::FILE* progress);

}  // namespace exc::app
