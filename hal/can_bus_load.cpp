#include "hal/can_bus_load.hpp"

namespace exc::hal {

std::uint16_t can_crc15(const std::uint8_t* bits, int count) {
  std::uint16_t crc = 0;
  for (int i = 0; i < count; ++i) {
    const bool next = ((crc >> 14) & 1u) != bits[i];
    crc = static_cast<std::uint16_t>((crc << 1) & 0x7FFFu);
    if (next) crc ^= 0x4599u;
  }
  return crc;
}

int classical_frame_bits(std::uint32_t id, std::uint8_t dlc, const std::uint8_t* data) {
  // SOF, 11-bit ID, RTR, IDE, r0, DLC, data, then the CRC over all of these: at most 19 + 64 + 15.
  std::uint8_t bits[19 + 64 + 15];
  int n = 0;
  const auto put = [&](std::uint32_t value, int width) {
    for (int b = width - 1; b >= 0; --b) bits[n++] = static_cast<std::uint8_t>((value >> b) & 1u);
  };
  const int bytes = dlc > 8 ? 8 : dlc;
  put(0, 1);           // SOF (dominant)
  put(id & 0x7FFu, 11);
  put(0, 1);           // RTR: data frame
  put(0, 1);           // IDE: standard
  put(0, 1);           // r0
  put(dlc & 0xFu, 4);
  for (int i = 0; i < bytes; ++i) put(data[i], 8);
  put(can_crc15(bits, n), 15);
  // After five equal bits the transmitter inserts their complement, which starts the next run.
  int stuff = 0, run = 0;
  std::uint8_t last = 2;
  for (int i = 0; i < n; ++i) {
    if (bits[i] == last) {
      ++run;
    } else {
      last = bits[i];
      run = 1;
    }
    if (run == 5) {
      ++stuff;
      last = static_cast<std::uint8_t>(!last);
      run = 1;
    }
  }
  // CRC delimiter, ACK slot, ACK delimiter, EOF (7) and intermission (3) are never stuffed.
  return n + stuff + 1 + 1 + 1 + 7 + 3;
}

}  // namespace exc::hal
