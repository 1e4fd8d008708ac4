#pragma once
// One CAN frame as the HAL moves it, classical or CAN FD: plain data, no ownership, copied by value.
#include <cstdint>

namespace exc::hal {

inline constexpr int kCanMaxLength = 8;     // classical CAN payload, bytes
inline constexpr int kCanFdMaxLength = 64;  // CAN FD payload, bytes

struct CanFrame {
  std::uint32_t id = 0;        // 11-bit identifier (bits above 0x7FF are never valid here)
  std::uint8_t len = 0;        // payload length in bytes (not the DLC code): 0..8, FD also 12..64
  bool fd = false;             // CAN FD frame (FDF); false: classical
  bool brs = false;            // FD only: bit-rate switch, the data phase at the data bit rate
  std::uint8_t data[kCanFdMaxLength] = {};  // payload; bytes at and beyond len are zero when sent by this HAL
  std::int64_t timestamp_ns = 0;  // receive time, CLOCK_MONOTONIC ns (0 when the backend has none)
  // The frame's exact on-wire time (frame_time_ns) as its sender timed it, carried with the frame so
  // that a receiver on an in-process bus does not time the same bits again; 0: not known (a frame
  // from a kernel socket, one built by hand, one whose bits a bus changed after it was timed), and the
  // receiver times it itself.
  std::int64_t wire_ns = 0;
};

// The payload lengths a frame can have: 0..8 bytes, and for CAN FD the DLC codes 9..15 mean 12, 16,
// 20, 24, 32, 48 and 64 bytes.
constexpr bool valid_length(std::uint8_t len, bool fd) {
  if (len <= kCanMaxLength) return true;
  if (!fd) return false;
  return len == 12 || len == 16 || len == 20 || len == 24 || len == 32 || len == 48 || len == 64;
}

// A frame this HAL can put on a bus: an 11-bit ID, a valid length, BRS only on FD frames.
constexpr bool sendable(const CanFrame& frame) {
  return frame.id <= 0x7FF && valid_length(frame.len, frame.fd) && (frame.fd || !frame.brs);
}

// The DLC code of a valid length (ISO 11898-1: 0..8 as is, then 12 -> 9 ... 64 -> 15).
constexpr std::uint8_t dlc_of_length(std::uint8_t len) {
  if (len <= 8) return len;
  if (len <= 24) return static_cast<std::uint8_t>(9 + (len - 12) / 4);  // 12, 16, 20, 24 -> 9..12
  return len <= 32 ? 13 : (len <= 48 ? 14 : 15);
}

}  // namespace exc::hal
