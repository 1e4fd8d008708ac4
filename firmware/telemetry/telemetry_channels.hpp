#pragma once
// The telemetry channels and their LCM names. A run that compares controllers writes both into one
// log by giving each publisher a channel suffix: EXC_STATE/pid and EXC_STATE/adaptive.
#include <cstddef>
#include <cstdint>

namespace exc::telemetry {

enum class Channel : std::uint16_t {
  state = 0,        // exlcm::machine_state_t, every control cycle
  command,          // exlcm::command_t, every control cycle
  controller,       // exlcm::controller_state_t, every control cycle
  timing,           // exlcm::timing_t, periodically, one message per counter
  can_stats,        // exlcm::can_stats_t, periodically, one message per bus end
  fault,            // exlcm::fault_t, when a fault is raised or cleared
  telemetry_stats,  // exlcm::telemetry_stats_t, about once a second, from the telemetry thread
};
inline constexpr std::size_t channel_count = 7;

// The channels published every control cycle: the bulk of a log, and what a long run may record at a
// lower rate (TelemetryConfig::per_cycle_every).
constexpr bool per_cycle(Channel channel) {
  return channel == Channel::state || channel == Channel::command || channel == Channel::controller;
}
// The largest per_cycle_every a program accepts: every 10 s at 1 kHz.
inline constexpr long kMaxPerCycleEvery = 10000;

// The base LCM channel name (without suffix).
constexpr const char* channel_base_name(Channel channel) {
  switch (channel) {
    case Channel::state: return "EXC_STATE";
    case Channel::command: return "EXC_COMMAND";
    case Channel::controller: return "EXC_CONTROLLER";
    case Channel::timing: return "EXC_TIMING";
    case Channel::can_stats: return "EXC_CAN_STATS";
    case Channel::fault: return "EXC_FAULT";
    case Channel::telemetry_stats: return "EXC_TELEMETRY_STATS";
  }
  return "EXC_UNKNOWN";
}

}  // namespace exc::telemetry
