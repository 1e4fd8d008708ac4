#pragma once
// The firmware loop's timing counters, PX4 perf_counter style: one per stage of end_cycle, the
// whole cycle and a real-time loop's wake-up interval, each published on EXC_TIMING under its stage
// number (lcmtypes/timing_t.lcm), with the bus's counts and load on EXC_CAN_STATS. Read from
// hal::monotonic_now_ns: nanoseconds on a host, instructions on the emulated Cortex-M7 (whose clock
// counts one nanosecond per instruction: docs/target.md).
#include <cstdint>

#include "diagnostics/can_stats_message.hpp"
#include "diagnostics/perf_counter.hpp"
#include "exlcm/can_stats_t.hpp"
#include "exlcm/timing_t.hpp"
#include "hal/can_ports.hpp"

namespace exc::telemetry {
class TelemetrySink;
}

namespace exc::diagnostics {

// Cycles between the counter messages (EXC_TIMING per stage, EXC_CAN_STATS). Each round's messages
// go out over consecutive cycles, one a cycle from cycle k x kCounterPeriod on (the parts below), so
// no cycle pays for all of them: re-binning a counter's histogram and encoding its 600 bytes cost
// about 9,500 instructions on the Cortex-M7 (docs/target.md), ten of them twice its budget.
inline constexpr int kCounterPeriod = 100;

// timing_t.stage of each counter.
enum class LoopStage : std::int8_t {
  cycle = 0,      // the whole end_cycle: read to telemetry encoded
  read = 1,       // the bus read and the supervisor's take of the operator's and the machine's signals
  update = 2,     // estimate, path, law, the stages after it and the monitors (7 to 10 together)
  write = 3,      // the command frames encoded and sent
  interval = 5,   // a real-time loop's wake-up to wake-up
  telemetry = 6,  // the cycle's messages encoded
  estimate = 7,   // the state estimator and the path's desired motion
  law = 8,        // the control law
  actuation = 9,  // the stages after the law: blend and lag lead, or the valve stage
  monitors = 10,  // the supervisor's checks of the law's output, the pressures, the pumps' demand,
                  // the flow and the spools
};

// The stages published each round, the interval aside (it is published once a real-time loop has one).
inline constexpr int kTimingStages = 9;
// A round's parts: each stage, the interval, the bus's counts (EXC_CAN_STATS). Each part is made in
// one cycle and encoded and published in the next (kCounterSteps cycles a round): either half costs
// about 4,000 instructions on the Cortex-M7.
inline constexpr int kCounterParts = kTimingStages + 2;
inline constexpr int kCounterSteps = 2 * kCounterParts;

struct LoopCounters {
  explicit LoopCounters(double period);
  PerfCounter& operator[](LoopStage s) { return counter(s); }
  const PerfCounter& operator[](LoopStage s) const { return const_cast<LoopCounters*>(this)->counter(s); }

  // Step `step` of a round (0 .. kCounterSteps - 1): part step / 2 (the stages in turn, the interval
  // with the sleeper's deadline counters once a real-time loop has one, the bus's counts) made on the
  // even step, published on the odd one; window_end is the end of the bus-load window (s), utime the
  // message's stamp (the making step's).
  void publish_step(int step, telemetry::TelemetrySink& telemetry, const hal::FirmwareCanPort& port, double window_end,
                    std::int64_t utime);
  // The whole round at once (a run's end); a part made and not yet published is left out, the round
  // has it afresh.
  void publish(telemetry::TelemetrySink& telemetry, const hal::FirmwareCanPort& port, double window_end, std::int64_t utime) {
    made_ = Made::none;
    for (int step = 0; step < kCounterSteps; ++step) publish_step(step, telemetry, port, window_end, utime);
  }

  PerfCounter cycle, read, update, write, interval, telemetry, estimate, law, actuation, monitors;
  std::uint64_t deadline_overruns = 0, skipped_deadlines = 0;  // the real-time sleeper's, as last reported

 private:
  PerfCounter& counter(LoopStage s);
  BusLoadWindow bus_load_;
  // The part made and not yet published.
  enum class Made : std::uint8_t { none, timing, can_stats } made_ = Made::none;
  exlcm::timing_t timing_;
  exlcm::can_stats_t can_stats_;
};

}  // namespace exc::diagnostics
