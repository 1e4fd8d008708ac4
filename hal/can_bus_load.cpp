#include "hal/can_bus_load.hpp"

namespace exc::hal {
namespace {

// Bit stuffing as a state machine: after five equal bits the transmitter inserts their complement,
// which starts the next run. The state between bits is the last bit's value and the length of its
// run (1..4; a run of 5 has just been stuffed, so the stuff bit's run of 1 follows), or "no bit yet"
// before SOF: ten states, of which (0, 0) is the start. Stepping the bits one by one is the
// definition; the table below steps a whole byte (most significant bit first) at once, with the stuff
// bits it needs, so a frame costs one look-up per data byte instead of eight bit steps and a bit array.
struct StuffState {
  std::uint8_t last = 0;  // value of the last bit
  std::uint8_t run = 0;   // equal bits in a row, 0 before the first bit
  constexpr std::uint8_t index() const { return static_cast<std::uint8_t>(5 * last + run); }
};

constexpr StuffState state_of(std::uint8_t index) {
  return StuffState{static_cast<std::uint8_t>(index / 5), static_cast<std::uint8_t>(index % 5)};
}

// One bit: returns 1 when a stuff bit follows it.
constexpr int stuff_step(StuffState& s, std::uint8_t bit) {
  if (s.run != 0 && bit == s.last) {
    ++s.run;
  } else {
    s.last = bit;
    s.run = 1;
  }
  if (s.run < 5) return 0;
  s.last = static_cast<std::uint8_t>(!s.last);
  s.run = 1;
  return 1;
}

// Per state and byte: the stuff bits inserted while the byte's eight bits go out (0..2) in the low two
// bits, the state after it above them.
struct ByteStuffTable {
  std::uint8_t entry[10][256];
  constexpr ByteStuffTable() : entry{} {
    for (int st = 0; st < 10; ++st) {
      for (int byte = 0; byte < 256; ++byte) {
        StuffState s = state_of(static_cast<std::uint8_t>(st));
        int stuff = 0;
        for (int b = 7; b >= 0; --b) stuff += stuff_step(s, static_cast<std::uint8_t>((byte >> b) & 1));
        entry[st][byte] = static_cast<std::uint8_t>(s.index() << 2 | stuff);
      }
    }
  }
};
constexpr ByteStuffTable kByteStuff;

// A stuffing count in progress over a frame's bits, most significant first.
struct StuffCounter {
  std::uint8_t state = 0;  // StuffState::index(); 0: before SOF
  int stuff = 0;
  // The `width` (< 8) low bits of `value`, one by one; whole bytes go through the table.
  void bits(std::uint32_t value, int width) {
    StuffState s = state_of(state);
    for (int b = width - 1; b >= 0; --b) stuff += stuff_step(s, static_cast<std::uint8_t>((value >> b) & 1u));
    state = s.index();
  }
  void bytes(const std::uint8_t* data, int count) {
    for (int i = 0; i < count; ++i) byte(data[i]);
  }
  void byte(std::uint8_t value) {
    const std::uint8_t e = kByteStuff.entry[state][value];
    stuff += e & 3;
    state = static_cast<std::uint8_t>(e >> 2);
  }
};

// CRC-15 of CAN (polynomial 0x4599, initial 0), bit by bit and a byte (most significant bit first) at
// a time; the byte table is built from the bitwise definition.
constexpr std::uint16_t crc15_bit(std::uint16_t crc, unsigned bit) {
  const bool next = ((crc >> 14) & 1u) != bit;
  crc = static_cast<std::uint16_t>((crc << 1) & 0x7FFFu);
  return next ? static_cast<std::uint16_t>(crc ^ 0x4599u) : crc;
}

struct Crc15Table {
  std::uint16_t entry[256];
  constexpr Crc15Table() : entry{} {
    for (int i = 0; i < 256; ++i) {
      std::uint16_t crc = 0;
      for (int b = 7; b >= 0; --b) crc = crc15_bit(crc, static_cast<unsigned>((i >> b) & 1));
      entry[i] = crc;
    }
  }
};
constexpr Crc15Table kCrc15;

// The CRC register after a byte: its top 8 bits meet the byte, the rest shifts on (linearity of the CRC).
constexpr std::uint16_t crc15_byte(std::uint16_t crc, std::uint8_t byte) {
  return static_cast<std::uint16_t>(((crc << 8) & 0x7FFFu) ^ kCrc15.entry[(crc >> 7 ^ byte) & 0xFFu]);
}

constexpr std::uint16_t crc15_bits(std::uint16_t crc, std::uint32_t value, int width) {
  for (int b = width - 1; b >= 0; --b) crc = crc15_bit(crc, (value >> b) & 1u);
  return crc;
}

}  // namespace

std::uint16_t can_crc15(const std::uint8_t* bits, int count) {
  std::uint16_t crc = 0;
  for (int i = 0; i < count; ++i) crc = crc15_bit(crc, bits[i]);
  return crc;
}

int classical_frame_bits(std::uint32_t id, std::uint8_t len, const std::uint8_t* data) {
  // SOF, 11-bit ID, RTR, IDE, r0 (all dominant but the ID), DLC: 19 bits; then the data and the CRC
  // over all of these, stuffed alike.
  const int bytes = len > 8 ? 8 : len;
  const std::uint32_t header = (id & 0x7FFu) << 7 | static_cast<std::uint32_t>(bytes);  // SOF .. DLC
  StuffCounter s;
  s.byte(static_cast<std::uint8_t>(header >> 11));
  s.byte(static_cast<std::uint8_t>(header >> 3));
  s.bits(header & 0x7u, 3);
  s.bytes(data, bytes);
  std::uint16_t crc = crc15_bits(0, header, 19);
  for (int i = 0; i < bytes; ++i) crc = crc15_byte(crc, data[i]);
  s.byte(static_cast<std::uint8_t>(crc >> 7));
  s.bits(crc & 0x7Fu, 7);
  // CRC delimiter, ACK slot, ACK delimiter, EOF (7) and intermission (3) are never stuffed.
  return 19 + 8 * bytes + 15 + s.stuff + 1 + 1 + 1 + 7 + 3;
}

CanFdFrameBits canfd_frame_bits(std::uint32_t id, std::uint8_t len, const std::uint8_t* data, bool brs) {
  const int bytes = len > kCanFdMaxLength ? kCanFdMaxLength : len;
  // SOF, ID, RRS (dominant), IDE (standard), FDF (recessive), res: bits 0 .. 15.
  const std::uint32_t arbitration_bits = (id & 0x7FFu) << 4 | 0x2u;
  // BRS (bit 16), ESI (error active), DLC: a stuff bit after BRS goes out after the switch, at the
  // data rate, so the count splits after bit 15.
  const std::uint32_t control_bits = (brs ? 1u : 0u) << 5 | dlc_of_length(static_cast<std::uint8_t>(bytes));
  StuffCounter s;
  s.byte(static_cast<std::uint8_t>(arbitration_bits >> 8));
  s.byte(static_cast<std::uint8_t>(arbitration_bits));
  const int stuff_arbitration = s.stuff;
  s.bits(control_bits, 6);
  s.bytes(data, bytes);
  const int stuff_data = s.stuff - stuff_arbitration;
  constexpr int kFirstDataPhaseBit = 17;
  const int tail = 1 + 1 + 1 + 7 + 3;  // CRC delimiter, ACK, ACK delimiter, EOF, intermission
  const int arbitration = kFirstDataPhaseBit + stuff_arbitration;
  const int data_phase = (22 + 8 * bytes - kFirstDataPhaseBit) + stuff_data + canfd_crc_field_bits(bytes);
  if (!brs) return {arbitration + data_phase + tail, 0};
  return {arbitration + tail, data_phase};
}

std::int64_t frame_time_ns(const CanFrame& frame) {
  if (!frame.fd) return classical_frame_bits(frame.id, frame.len, frame.data) * kNominalBitNs;
  return canfd_frame_bits(frame.id, frame.len, frame.data, frame.brs).duration_ns();
}

}  // namespace exc::hal
