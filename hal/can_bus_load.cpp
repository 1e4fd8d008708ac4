#include "hal/can_bus_load.hpp"

namespace exc::hal {
namespace {

// Stuff bits the transmitter inserts into bits[0 .. count): after five equal bits their complement,
// which starts the next run. Stuff bits after a bit with index below `split` are counted in `before`,
// the others in `after`.
void count_stuff_bits(const std::uint8_t* bits, int count, int split, int& before, int& after) {
  before = after = 0;
  int run = 0;
  std::uint8_t last = 2;
  for (int i = 0; i < count; ++i) {
    if (bits[i] == last) {
      ++run;
    } else {
      last = bits[i];
      run = 1;
    }
    if (run == 5) {
      ++(i < split ? before : after);
      last = static_cast<std::uint8_t>(!last);
      run = 1;
    }
  }
}

// Appends `value`'s low `width` bits, most significant first.
struct BitStream {
  std::uint8_t* bits;
  int n = 0;
  void put(std::uint32_t value, int width) {
    for (int b = width - 1; b >= 0; --b) bits[n++] = static_cast<std::uint8_t>((value >> b) & 1u);
  }
};

}  // namespace

std::uint16_t can_crc15(const std::uint8_t* bits, int count) {
  std::uint16_t crc = 0;
  for (int i = 0; i < count; ++i) {
    const bool next = ((crc >> 14) & 1u) != bits[i];
    crc = static_cast<std::uint16_t>((crc << 1) & 0x7FFFu);
    if (next) crc ^= 0x4599u;
  }
  return crc;
}

int classical_frame_bits(std::uint32_t id, std::uint8_t len, const std::uint8_t* data) {
  // SOF, 11-bit ID, RTR, IDE, r0, DLC, data, then the CRC over all of these: at most 19 + 64 + 15.
  std::uint8_t storage[19 + 64 + 15];
  BitStream s{storage};
  const int bytes = len > 8 ? 8 : len;
  s.put(0, 1);           // SOF (dominant)
  s.put(id & 0x7FFu, 11);
  s.put(0, 1);           // RTR: data frame
  s.put(0, 1);           // IDE: standard
  s.put(0, 1);           // r0
  s.put(static_cast<std::uint32_t>(bytes), 4);
  for (int i = 0; i < bytes; ++i) s.put(data[i], 8);
  s.put(can_crc15(storage, s.n), 15);
  int stuff = 0, unused = 0;
  count_stuff_bits(storage, s.n, s.n, stuff, unused);
  // CRC delimiter, ACK slot, ACK delimiter, EOF (7) and intermission (3) are never stuffed.
  return s.n + stuff + 1 + 1 + 1 + 7 + 3;
}

CanFdFrameBits canfd_frame_bits(std::uint32_t id, std::uint8_t len, const std::uint8_t* data, bool brs) {
  // SOF .. DLC (22 bits) and at most 64 data bytes: the dynamically stuffed part.
  std::uint8_t storage[22 + 8 * kCanFdMaxLength];
  BitStream s{storage};
  const int bytes = len > kCanFdMaxLength ? kCanFdMaxLength : len;
  s.put(0, 1);            // SOF
  s.put(id & 0x7FFu, 11);
  s.put(0, 1);            // RRS (dominant)
  s.put(0, 1);            // IDE: standard
  s.put(1, 1);            // FDF: FD format (recessive)
  s.put(0, 1);            // res
  s.put(brs ? 1 : 0, 1);  // BRS
  s.put(0, 1);            // ESI: error active
  s.put(dlc_of_length(static_cast<std::uint8_t>(bytes)), 4);
  for (int i = 0; i < bytes; ++i) s.put(data[i], 8);
  // A stuff bit inserted after BRS (index 16) goes out after the switch, at the data rate.
  constexpr int kFirstDataPhaseBit = 17;
  int stuff_arbitration = 0, stuff_data = 0;
  count_stuff_bits(storage, s.n, kFirstDataPhaseBit - 1, stuff_arbitration, stuff_data);
  const int tail = 1 + 1 + 1 + 7 + 3;  // CRC delimiter, ACK, ACK delimiter, EOF, intermission
  const int arbitration = kFirstDataPhaseBit + stuff_arbitration;
  const int data_phase = (s.n - kFirstDataPhaseBit) + stuff_data + canfd_crc_field_bits(bytes);
  if (!brs) return {arbitration + data_phase + tail, 0};
  return {arbitration + tail, data_phase};
}

std::int64_t frame_time_ns(const CanFrame& frame) {
  if (!frame.fd) return classical_frame_bits(frame.id, frame.len, frame.data) * kNominalBitNs;
  return canfd_frame_bits(frame.id, frame.len, frame.data, frame.brs).duration_ns();
}

}  // namespace exc::hal
