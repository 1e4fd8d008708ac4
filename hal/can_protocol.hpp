#pragma once
// The excavator CAN protocol as data: every message and signal of hal/excavator.dbc, in the same
// order and with the same layout. The codec is driven by these tables and a test parses the DBC and
// holds the tables to it, so the DBC stays the single specification.
#include <array>
#include <cstddef>
#include <cstdint>

#include "hal/excavator_interface.hpp"

namespace exc::hal {

// operator_station: an operator station or remote e-stop kit; it only sends (SUPERVISOR).
enum class Node : std::uint8_t { firmware, plant, operator_station };
// The DBC's node name (BU_): "Firmware", "Plant", "Operator".
const char* to_string(Node node);

// One DBC signal, Intel byte order: `start` is the bit number of the least significant bit, bit k of
// the frame being bit k % 8 of byte k / 8. physical = raw * factor + offset, allowed in [min, max].
struct SignalSpec {
  const char* name;
  std::uint16_t start;
  std::uint8_t length;
  bool is_signed;
  double factor;
  double offset;
  double min;
  double max;
  const char* unit;
  // Derived from the fields above when the table is built (the codec's per-signal work, every frame):
  // the field's mask, the raw values it can hold, and whether it lies in the 8-byte word from its
  // first byte within the 64-byte payload (every signal of the protocol does).
  std::uint64_t raw_mask = length >= 64 ? ~0ULL : ((1ULL << length) - 1);
  std::int64_t raw_min = is_signed ? -(std::int64_t{1} << (length - 1)) : 0;
  std::int64_t raw_max = is_signed ? (std::int64_t{1} << (length - 1)) - 1 : static_cast<std::int64_t>(raw_mask);
  bool one_word = length != 0 && length <= 64 && start % 8 + length <= 64 && start / 8 + 8 <= 64;
};

// Which command set a frame belongs to (the DBC attribute ExcCommandSet); the three are exclusive.
enum class CommandSet : std::uint8_t { none, effort, valve, pilot };

// One DBC message. signals[0] is always Counter (bits 0..3) and signals[signal_count - 1] is always
// Crc (the last byte); the data signals lie in between.
struct MessageSpec {
  const char* name;
  std::uint32_t id;
  std::uint8_t length;  // payload bytes (the DBC's message size)
  bool fd;              // DBC VFrameFormat StandardCAN_FD
  bool brs;             // DBC CANFD_BRS: data phase at the data bit rate
  Node sender;
  int cycle_ms;  // 0: event-driven
  CommandSet command_set;
  const SignalSpec* signals;
  std::uint8_t signal_count;

  std::uint8_t data_signal_count() const { return static_cast<std::uint8_t>(signal_count - 2); }
  const SignalSpec& data_signal(std::size_t i) const { return signals[i + 1]; }
};

namespace can_id {
inline constexpr std::uint32_t fw_emergency = 0x010;
inline constexpr std::uint32_t plant_emergency = 0x011;
inline constexpr std::uint32_t supervisor = 0x012;
inline constexpr std::uint32_t sync = 0x080;
inline constexpr std::uint32_t cmd_effort = 0x100;
inline constexpr std::uint32_t cmd_valve = 0x102;
inline constexpr std::uint32_t cmd_pilot = 0x103;
inline constexpr std::uint32_t sens_machine = 0x180;
inline constexpr std::uint32_t fw_heartbeat = 0x701;
inline constexpr std::uint32_t plant_heartbeat = 0x702;
}  // namespace can_id

// SUPERVISOR's Command signal (SupervisorCommand, hal/excavator_interface.hpp).
const char* to_string(SupervisorCommand command);

inline constexpr std::size_t kMessageCount = 10;
// The most data signals of any message (SENS_MACHINE): a buffer of this size holds any decoded frame.
inline constexpr std::size_t kMaxDataSignals = 25;
inline constexpr std::int64_t kCyclePeriodNs = 1'000'000;  // one SYNC per millisecond
inline constexpr int kHeartbeatPeriodCycles = 100;
inline constexpr int kEmergencyRepeatCycles = 10;

// All messages, in the order of the DBC.
const std::array<MessageSpec, kMessageCount>& protocol_messages();

// Index of `id` in protocol_messages(), or -1 for an unknown identifier.
int message_index(std::uint32_t id);

// The message with identifier `id`, or nullptr.
const MessageSpec* find_message(std::uint32_t id);

}  // namespace exc::hal
