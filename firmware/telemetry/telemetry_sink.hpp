#pragma once
// The loop's side of telemetry: publish(channel, msg) stamps the channel's sequence number, leaves
// out what a per-cycle decimation says to (per_cycle_every), encodes the message with the lcm-gen
// encoder into a fixed buffer and hands the bytes to put(), which a sink implements: the host's
// TelemetryPublisher (a lock-free ring drained into LCM by a thread), or the Cortex-M7 image's link
// to the host (docs/target.md). No LCM library, no thread, no allocation: the encoders are lcm-gen's
// header-only C++.
#include <array>
#include <cstddef>
#include <cstdint>

#include "telemetry/telemetry_channels.hpp"

namespace exc::telemetry {

class TelemetrySink {
 public:
  // The largest encoding a sink takes (timing_t, the largest exlcm type, is 593 bytes).
  static constexpr std::size_t kMaxMessageBytes = 1024;

  // Allocation-free. Hands the message's encoding to the sink with its seq this channel's next
  // sequence number (0, 1, 2, ...; msg.seq itself is not read); false if it was refused (too large,
  // or the sink was full).
  template <class Msg>
  bool publish(Channel channel, const Msg& msg) {
    const auto index = static_cast<std::size_t>(channel);
    if (index >= channel_count) return false;
    if (every_[index] > 1 && offered_[index]++ % every_[index] != 0) return true;  // left out on purpose
    // Encoded as given, then its seq stamped into the bytes (stamp_sequence): no copy of the message.
    const int size = msg.encode(encode_buffer_.data(), 0, static_cast<int>(kMaxMessageBytes));
    if (size < 24) {
      note_too_large();
      return false;
    }
    stamp_sequence(index, encode_buffer_.data());
    return put(index, encode_buffer_.data(), static_cast<std::size_t>(size));
  }

  // An already encoded exlcm message (another sink's, e.g. an emulated target's over its link), stamped
  // with this sink's sequence number for its channel and handed on as publish() does: one sequence
  // per channel in a log, whoever encoded the messages. seq is every exlcm type's third field, after
  // the 8-byte fingerprint and utime: bytes 16-23, big-endian.
  bool publish_encoded(Channel channel, std::uint8_t* bytes, std::size_t size) {
    const auto index = static_cast<std::size_t>(channel);
    if (index >= channel_count || size < 24) return false;
    if (size > kMaxMessageBytes) {
      note_too_large();
      return false;
    }
    if (every_[index] > 1 && offered_[index]++ % every_[index] != 0) return true;
    stamp_sequence(index, bytes);
    return put(index, bytes, size);
  }

 protected:
  // Record the per-cycle channels (per_cycle(): EXC_STATE, EXC_COMMAND, EXC_CONTROLLER) every Nth
  // message only, from the first; the others whole. seq counts the recorded ones.
  explicit TelemetrySink(std::uint32_t per_cycle_every) {
    for (std::size_t i = 0; i < channel_count; ++i)
      every_[i] = per_cycle(static_cast<Channel>(i)) && per_cycle_every > 1 ? per_cycle_every : 1;
  }
  ~TelemetrySink() = default;
  TelemetrySink(const TelemetrySink&) = delete;
  TelemetrySink& operator=(const TelemetrySink&) = delete;

  // One encoded message of channel `channel` (its index): false when the sink refused it.
  virtual bool put(std::size_t channel, const std::uint8_t* bytes, std::size_t size) = 0;
  virtual void note_too_large() {}

 private:
  // This channel's next sequence number into an encoding's seq (bytes 16-23, big-endian).
  void stamp_sequence(std::size_t index, std::uint8_t* bytes) {
    const std::uint64_t seq = next_sequence_[index]++;
    for (int i = 0; i < 8; ++i) bytes[16 + i] = static_cast<std::uint8_t>(seq >> (56 - 8 * i));
  }

  std::array<std::uint64_t, channel_count> next_sequence_{};
  std::array<std::uint64_t, channel_count> offered_{};  // messages offered per channel (per_cycle_every)
  std::array<std::uint32_t, channel_count> every_{};    // record every Nth (1: all)
  alignas(8) std::array<std::uint8_t, kMaxMessageBytes> encode_buffer_{};
};

}  // namespace exc::telemetry
