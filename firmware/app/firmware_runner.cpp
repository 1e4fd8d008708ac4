#include "app/firmware_runner.hpp"

#include <algorithm>

#include "hal/clock.hpp"

namespace exc::app {

namespace {

std::string number(const char* format, double value) {
  char b[48];
  std::snprintf(b, sizeof b, format, value);
  return b;
}

void print_transition(const FirmwareNode& node, std::FILE* progress) {
  const safety::Transition& t = node.last_transition();
  if (!t.changed || !progress) return;
  const bool stopped = t.to == safety::Mode::safe_stop;
  std::fprintf(progress, "excavator-firmware: cycle %llu (%.3f s): %s -> %s: %s%s%s\n",
               static_cast<unsigned long long>(node.cycle()), node.time(), safety::to_string(t.from),
               safety::to_string(t.to), t.reason, stopped ? ": " : "", stopped ? node.supervisor().last_fault_text() : "");
  std::fflush(progress);
}

}  // namespace

RunnerOutcome run_firmware(FirmwareNode& node, hal::CanBus& bus, const RunnerOptions& options,
                           const std::atomic<int>& stop_requests, std::FILE* progress) {
  RunnerOutcome outcome;
  const std::int64_t period_ns = options.period_ns;
  const double period_s = static_cast<double>(period_ns) * 1e-9;
  hal::DeadlineSleeper sleeper(period_ns);
  std::int64_t last_wake = 0;
  bool grid_started = false;
  std::int64_t request_cycle = -1;  // cycle of the stop request
  std::int64_t still_cycle = -1;    // first cycle after it with the path at rest: the hold's time counts from here
  RunPhases phases;  // after each cycle, outside the node's cycle and its timing
  for (std::int64_t k = 0; k < options.cycles && stop_requests.load() < 2; ++k) {
    if (stop_requests.load() == 1 && request_cycle < 0) {
      outcome.stop_requested = true;
      // A tracking machine is brought to hold first; in any other mode there is nothing to stop.
      if (!node.tracking()) break;
      node.request_stop();
      request_cycle = k;
      if (progress)
        std::fprintf(progress,
                     "excavator-firmware: stop requested: decelerating along the path, then holding for %.2f s, "
                     "then exiting\n",
                     options.stop_hold_s);
    }
    // The node starts the deceleration in the request's cycle: from the next one on, a node no
    // longer slowing its path stands (or was stopped by a fault).
    if (request_cycle >= 0 && still_cycle < 0 && k > request_cycle && !node.stopping_on_path()) still_cycle = k;
    if (still_cycle >= 0 && static_cast<double>(k - still_cycle) * period_s > options.stop_hold_s) break;
    if (options.realtime && grid_started) {
      sleeper.wait_next();
      const std::int64_t now = hal::monotonic_now_ns();
      node.record_wakeup(now - last_wake, sleeper.overruns(), sleeper.skipped_periods());
      last_wake = now;
    }
    const std::int64_t cycle_start = hal::monotonic_now_ns();
    node.begin_cycle();
    // Until the plant has answered once, a cycle waits as long as start-up takes (a slow first
    // cycle must not desynchronise the counters); afterwards the sensor wait feeds the watchdog.
    std::int64_t deadline = cycle_start + (node.has_sensors() ? options.sensor_wait_ns : options.startup_wait_ns);
    if (options.realtime && grid_started) deadline = std::min(deadline, sleeper.next_deadline_ns() - period_ns / 10);
    while (!node.receive()) {
      const std::int64_t left = deadline - hal::monotonic_now_ns();
      if (left <= 0) break;
      bus.wait_readable(left);
    }
    node.end_cycle();
    const std::array<double, 4>& sensed = node.sensors().position;
    phases.add(node.time(), period_s, node.mode(), node.tracking(), Vec4(sensed[0], sensed[1], sensed[2], sensed[3]),
               node.q_desired());
    if (options.realtime && !grid_started && node.has_sensors()) {
      // The deadline grid starts once the plant has answered: start-up is not a missed deadline.
      grid_started = true;
      last_wake = hal::monotonic_now_ns();
      sleeper.start(last_wake);
    }
    print_transition(node, progress);
  }
  // The run is over (its end, or a stop): the machine is left with its valves centred.
  node.send_safe_command(safety::FirmwareFault::exited);
  if (progress)
    std::fprintf(progress, "excavator-firmware: last command sent: valves centred, FW_EMERGENCY %s stop (%s)\n",
                 to_string(node.supervisor().emergency_sent() ? safety::StopKind::emergency : safety::StopKind::controlled),
                 node.mode() == safety::Mode::safe_stop ? node.supervisor().last_fault_text() : "firmware exited");
  node.publish_counters(true);

  outcome.cycles = node.cycle();
  outcome.tracking = phases.tracking();
  outcome.settle = phases.settle();
  outcome.hold = phases.hold();
  outcome.stop = phases.stop();
  outcome.overruns = sleeper.overruns();
  outcome.skipped_periods = sleeper.skipped_periods();
  // Missed deadlines come first when they are there: a loop that cannot hold its period starves
  // its own sensor watchdog, so the safe stop that follows is their consequence, named after them.
  const auto add = [&outcome](const std::string& reason) {
    outcome.failure += (outcome.failure.empty() ? "" : "; then ") + reason;
  };
  const double late = static_cast<double>(outcome.overruns + outcome.skipped_periods);
  if (options.realtime && late > options.max_overrun_fraction * static_cast<double>(outcome.cycles))
    add(std::to_string(outcome.overruns) + " of " + std::to_string(outcome.cycles) +
        " cycles woke after their deadline and " + std::to_string(outcome.skipped_periods) +
        " periods were skipped (allowed together: " + number("%g %%", options.max_overrun_fraction * 100) +
        " of the cycles): the loop cannot hold its " + number("%g ms", period_s * 1e3) + " period");
  if (node.measured_tracking().samples() == 0)
    add(std::string("the firmware never tracked (mode ") + safety::to_string(node.mode()) + ")");
  else if (node.supervisor().safe_stops() > 0)
    add(std::string("safe state: ") + node.supervisor().last_fault_text());
  else if (const std::string held = hold_failure(outcome.hold); !held.empty())
    add(held);
  outcome.ok = outcome.failure.empty();
  return outcome;
}

}  // namespace exc::app
