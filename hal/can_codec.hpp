#pragma once
// Encoding and validated decoding of the frames of hal/excavator.dbc (see can_protocol.hpp).
// Nothing here allocates or throws: it runs on the real-time path of both ends.
#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/can_frame.hpp"
#include "hal/can_protocol.hpp"

namespace exc::hal {

// CRC-8 SAE J1850: polynomial 0x1D, initial value 0xFF, final xor 0xFF (check value of "123456789"
// is 0x4B).
std::uint8_t crc8_sae_j1850(const std::uint8_t* bytes, std::size_t length);

// The protocol's frame checksum: CRC-8 SAE J1850 over the identifier (2 bytes, little-endian) and
// the payload bytes before the last one (the last byte carries the checksum). Covering the
// identifier catches a frame whose ID was corrupted into another valid ID.
std::uint8_t frame_checksum(std::uint32_t id, const std::uint8_t* payload, std::size_t payload_bytes_before_crc);

// Raw bit access in Intel (little-endian) order: bit k of the frame is bit k % 8 of byte k / 8, over
// the whole 64-byte payload. A field (length 1..64) reaching past the payload reads as 0 and is not
// written.
std::uint64_t read_raw_bits(const CanFrame& frame, unsigned start, unsigned length);
void write_raw_bits(CanFrame& frame, unsigned start, unsigned length, std::uint64_t raw);

// What encoding had to change: values outside the signal's [min, max] are saturated to the nearer
// end, non-finite values are sent as the in-range value nearest zero. Both are counted.
struct EncodeReport {
  std::uint8_t saturated = 0;
  std::uint8_t non_finite = 0;
  bool clean() const { return saturated == 0 && non_finite == 0; }
};

EncodeReport encode_signal(CanFrame& frame, const SignalSpec& signal, double value);
double decode_signal(const CanFrame& frame, const SignalSpec& signal);

// A whole message: values[i] is the physical value of message.data_signal(i). Sets id, length and the
// FD and BRS flags as the DBC gives them, zeroes unused bits, writes the counter (mod 16) and the
// checksum.
EncodeReport encode_message(const MessageSpec& message, std::uint8_t counter, const double* values, CanFrame& out);
// Decodes the data signals of a frame already validated by CanFrameCodec::accept.
void decode_message(const MessageSpec& message, const CanFrame& frame, double* values);
std::uint8_t frame_counter(const CanFrame& frame);

// wrong_format: the frame's length, or its FD flag (a classical frame for an FD message or the
// reverse), is not what the DBC gives. BRS is not checked: an FD frame without the switch carries the
// same content, only slower (the bus load counts it at its real length).
enum class RxVerdict : std::uint8_t { ok, unknown_id, wrong_format, corrupt, repeated, stale };
const char* to_string(RxVerdict verdict);

// Counters of received frames by verdict.
struct RxStats {
  std::uint64_t ok = 0;
  std::uint64_t unknown_id = 0;
  std::uint64_t wrong_format = 0;
  std::uint64_t corrupt = 0;
  std::uint64_t repeated = 0;
  std::uint64_t stale = 0;
  void record(RxVerdict verdict);
  std::uint64_t rejected() const { return unknown_id + wrong_format + corrupt + repeated + stale; }
};

// Receive-side validation: identifier, format (FD flag and length), checksum and rolling counter, in
// that order, so a frame
// is never decoded before it is known to be whole. Counters are tracked per message: with d = (new -
// last accepted) mod 16, d == 0 is a repeat, 1 <= d <= max_counter_gap is accepted (up to
// max_counter_gap - 1 frames lost), anything else is stale (older or out of order). The tracker
// restarts from the frame it sees (a) first, (b) after `resync_after` stale frames in a row, or (c)
// when the frame's timestamp is more than `fresh_after_ns` after the last accepted one (a sender that
// paused, e.g. a mode switch between command sets).
class CanFrameCodec {
 public:
  struct Config {
    std::uint8_t max_counter_gap = 3;
    std::uint8_t resync_after = 3;
    std::int64_t fresh_after_ns = 5 * kCyclePeriodNs;
  };

  CanFrameCodec();
  explicit CanFrameCodec(Config config);

  // Validates `frame`, counts the verdict in stats() and, when ok, points `message` at its spec.
  RxVerdict accept(const CanFrame& frame, const MessageSpec*& message);

  const RxStats& stats() const { return stats_; }
  const Config& config() const { return config_; }
  // Forgets every counter history (the next frame of each message starts a new sequence).
  void restart_sequences();

 private:
  struct Sequence {
    bool started = false;
    std::uint8_t last = 0;
    std::uint8_t stale_run = 0;
    std::int64_t last_ns = 0;
  };
  Config config_;
  RxStats stats_;
  std::array<Sequence, kMessageCount> sequences_{};
};

}  // namespace exc::hal
