#include "harness/log_volume.hpp"

#include "app/firmware_node.hpp"
#include "exlcm/can_stats_t.hpp"
#include "exlcm/command_t.hpp"
#include "exlcm/controller_state_t.hpp"
#include "exlcm/fault_t.hpp"
#include "exlcm/machine_state_t.hpp"
#include "exlcm/telemetry_stats_t.hpp"
#include "exlcm/timing_t.hpp"
#include "telemetry/telemetry_channels.hpp"

namespace exc::sim {
namespace {

// LCM's log event: sync word (4), event number (8), timestamp (8), channel length (4), data length (4).
constexpr std::uint64_t kEventHeaderBytes = 28;

// Bytes of one Msg on `channel` + `suffix` in an LCM log file: the event header, the channel's name,
// the message as lcm-gen encodes it (fixed-size types: the same for every message of the type).
template <class Msg>
std::uint64_t event_bytes(telemetry::Channel channel, const std::string& suffix) {
  const std::string name = telemetry::channel_base_name(channel) + suffix;
  return kEventHeaderBytes + name.size() + static_cast<std::uint64_t>(Msg{}.getEncodedSize());
}

}  // namespace

LogVolume lockstep_log_volume(std::int64_t cycles, const std::string& channel_suffix, std::uint32_t per_cycle_every) {
  using telemetry::Channel;
  LogVolume v;
  if (cycles <= 0) return v;
  const std::uint64_t n = static_cast<std::uint64_t>(cycles);
  const std::uint64_t every = per_cycle_every > 0 ? per_cycle_every : 1;
  v.per_cycle_messages = (n + every - 1) / every;  // cycles 1, 1 + every, ...
  v.per_cycle_bytes = event_bytes<exlcm::machine_state_t>(Channel::state, channel_suffix) +
                      event_bytes<exlcm::command_t>(Channel::command, channel_suffix) +
                      event_bytes<exlcm::controller_state_t>(Channel::controller, channel_suffix);
  // The counters: the firmware's parts one every other cycle from every kCounterPeriod-th on (its stages, its CAN
  // counters; the interval only in real time), the plant's step (EXC_TIMING stage 4) and CAN counters
  // every kCounterPeriod cycles (sim_plant/plant_node.cpp); each side's whole round once after the last.
  const std::uint64_t timing = event_bytes<exlcm::timing_t>(Channel::timing, channel_suffix);
  const std::uint64_t can = event_bytes<exlcm::can_stats_t>(Channel::can_stats, channel_suffix);
  std::uint64_t counters = (diagnostics::kTimingStages + 1) * timing + 2 * can;  // the end's
  counters += n / diagnostics::kCounterPeriod * (timing + can);                    // the plant's
  for (int part = 0; part < diagnostics::kCounterParts; ++part) {
    if (part == diagnostics::kTimingStages) continue;  // the interval: real time only
    const std::uint64_t p = static_cast<std::uint64_t>(part);
    const std::uint64_t published_at = 2 * p + 1;  // the step that publishes the part
    const std::uint64_t rounds = n >= diagnostics::kCounterPeriod + published_at ? (n - published_at) / diagnostics::kCounterPeriod : 0;
    counters += rounds * (part < diagnostics::kTimingStages ? timing : can);
  }
  // A run's start: init -> wait_sensors -> hold -> track, each change on EXC_FAULT (inactive).
  constexpr std::uint64_t kStartModeChanges = 3;
  v.bytes = v.per_cycle_messages * v.per_cycle_bytes + counters +
            kStartModeChanges * event_bytes<exlcm::fault_t>(Channel::fault, channel_suffix) +
            event_bytes<exlcm::telemetry_stats_t>(Channel::telemetry_stats, channel_suffix);
  return v;
}

}  // namespace exc::sim
