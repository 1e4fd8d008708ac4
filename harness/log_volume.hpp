#pragma once
// The size of the LCM log a lockstep run writes, known before the run (so that a run can state it
// and refuse a disk that cannot hold it): each message's encoded size as lcm-gen encodes it, in LCM's
// log event format (a 28-byte header and the channel name before the message), times the messages
// the firmware and the plant publish in the run's cycles.
#include <cstdint>
#include <string>

namespace exc::sim {

struct LogVolume {
  std::uint64_t bytes = 0;               // the whole run's log
  std::uint64_t per_cycle_messages = 0;  // recorded per channel: EXC_STATE, EXC_COMMAND, EXC_CONTROLLER each
  std::uint64_t per_cycle_bytes = 0;     // one recorded cycle of those three
};

// One controller's lockstep run of `cycles` cycles with telemetry on channels suffixed
// `channel_suffix` ("/pid"), the per-cycle channels recorded every `per_cycle_every`th cycle: the
// per-cycle messages, the counters every diagnostics::kCounterPeriod cycles and at the end (the firmware's
// stages and CAN counters, the plant's step and CAN counters), the mode changes of a run's start
// (EXC_FAULT) and the telemetry path's final counters. Later mode changes and faults, and the path's
// counters once per wall-clock second, are not counted: about 250 bytes each.
LogVolume lockstep_log_volume(std::int64_t cycles, const std::string& channel_suffix, std::uint32_t per_cycle_every);

}  // namespace exc::sim
