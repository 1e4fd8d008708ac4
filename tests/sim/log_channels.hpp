#pragma once
// An LCM log of the excavator's telemetry counted per channel, for the tests that check what a run
// logged: messages, sequence numbers and time stamps, read with LCM's own log reader.
#include <doctest/doctest.h>
#include <lcm/lcm-cpp.hpp>

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>

namespace exc::test {

// The channels the firmware and the plant publish (firmware/telemetry/telemetry_channels.hpp): the
// first three every control cycle, the others periodically or on events.
inline const char* const kPerCycleChannels[] = {"EXC_STATE", "EXC_COMMAND", "EXC_CONTROLLER"};
inline const char* const kOtherChannels[] = {"EXC_TIMING", "EXC_CAN_STATS", "EXC_FAULT", "EXC_TELEMETRY_STATS"};

// Per channel of an LCM log: messages, their sequence numbers and time stamps. Every exlcm type
// begins with the 8-byte fingerprint, int64 utime and int64 seq (big-endian, LCM's wire format), so
// both are read from the bytes as the .lcm files define them, without the generated code.
struct LogChannel {
  std::int64_t count = 0, first_seq = -1, last_seq = -1, seq_gaps = 0;
  std::int64_t out_of_order = 0;     // a sequence number not above the one before (a repeat or a step back)
  std::int64_t stamp_mismatches = 0;  // utime not (seq + 1) ms: cycle seq's message stamped with another cycle
  std::int64_t first_utime = -1, last_utime = -1;
  std::map<std::int64_t, std::int64_t> utime_steps;  // utime difference to the previous message: how often
};
inline std::map<std::string, LogChannel> read_log_channels(const std::filesystem::path& path) {
  std::map<std::string, LogChannel> channels;
  lcm::LogFile log(path.string(), "r");
  REQUIRE_MESSAGE(log.good(), "cannot read " << path.string());
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    LogChannel& c = channels[e->channel];
    REQUIRE(e->datalen >= 24);
    const auto* b = static_cast<const std::uint8_t*>(e->data);
    const auto field = [b](int at) {
      std::uint64_t v = 0;
      for (int i = at; i < at + 8; ++i) v = v << 8 | b[i];
      return static_cast<std::int64_t>(v);
    };
    const std::int64_t utime = field(8), seq = field(16);
    if (c.count == 0) {
      c.first_seq = seq;
      c.first_utime = utime;
    } else {
      if (seq != c.last_seq + 1) ++c.seq_gaps;
      if (seq <= c.last_seq) ++c.out_of_order;
      ++c.utime_steps[utime - c.last_utime];
    }
    if (utime != (seq + 1) * 1000) ++c.stamp_mismatches;
    c.last_seq = seq;
    c.last_utime = utime;
    ++c.count;
  }
  return channels;
}

}  // namespace exc::test
