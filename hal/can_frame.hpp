#pragma once
// One classical CAN frame as the HAL moves it: plain data, no ownership, copied by value.
#include <cstdint>

namespace exc::hal {

struct CanFrame {
  std::uint32_t id = 0;         // 11-bit identifier (bits above 0x7FF are never valid here)
  std::uint8_t dlc = 0;         // payload length in bytes, 0..8
  std::uint8_t data[8] = {};    // payload; bytes at and beyond dlc are zero when sent by this HAL
  std::int64_t timestamp_ns = 0;  // receive time, CLOCK_MONOTONIC ns (0 when the backend has none)
};

}  // namespace exc::hal
