#pragma once
// Frame lengths on the wire, exact and worst case, and the time they take on the bus: the bus budget
// and the measured bus load. Standard (11-bit) frames only.
//
// Classical CAN: 47 + 8 n bits for n data bytes without stuffing (SOF, ID, RTR, IDE, r0, DLC, data,
// CRC 15, CRC delimiter, ACK, ACK delimiter, EOF 7, intermission 3). Stuffing applies from SOF to the
// end of the CRC sequence, 34 + 8 n bits, and adds at worst one bit per 4 after the first:
// (34 + 8 n - 1) / 4. This is the figure of can-utils' canframelen (CFL_WORSTCASE) and of the
// kernel's can_frame_bits(); for n = 8 it gives 135 bits.
//
// CAN FD (ISO 11898-1:2015): SOF, ID 11, RRS, IDE, FDF, res, BRS, ESI, DLC 4, then the data. Dynamic
// stuff bits (after five equal bits, counting towards the next run) from SOF to the end of the data
// field, 22 + 8 n bits, at worst one per 4 after the first; then the stuff count (4 bits) and the CRC
// (17 bits up to 16 data bytes, 21 above) with a fixed stuff bit before the stuff count and after every
// 4 bits: 27 or 32 bits whatever the content. Then CRC delimiter, ACK, ACK delimiter, EOF 7 and the
// intermission 3. With the worst-case stuffing this is the kernel's can_frame_bits(fd, sff, worst,
// intermission, n) (include/linux/can/length.h as reworked in 2023): 67 bits for n = 0, 712 for
// n = 64.
//
// With bit-rate switch the bits from ESI to the end of the CRC run at the data rate, the rest at the
// nominal (arbitration) rate. The switch really happens at the sample points of BRS and of the CRC
// delimiter; counting BRS and the delimiter whole at the nominal rate overstates a frame by less than
// 2 nominal bits (2 us at 1 Mbit/s): the figures here err on the long side.
#include <cstdint>

#include "hal/can_frame.hpp"

namespace exc::hal {

// The protocol's bus (hal/excavator.dbc: Baudrate, BaudrateCANFD): arbitration at 1 Mbit/s, data phase
// at 5 Mbit/s. One bit in ns at each rate.
inline constexpr std::int64_t kNominalBitRate = 1'000'000;
inline constexpr std::int64_t kDataBitRate = 5'000'000;
inline constexpr std::int64_t kNominalBitNs = 1'000'000'000 / kNominalBitRate;
inline constexpr std::int64_t kDataBitNs = 1'000'000'000 / kDataBitRate;

// CRC-15 of CAN (polynomial 0x4599, initial 0) over `count` bits given MSB first.
std::uint16_t can_crc15(const std::uint8_t* bits, int count);

// The exact length in bits of one classical standard data frame as it goes on the wire: SOF to EOF
// plus the 3-bit intermission, with the stuff bits its content really needs (a stuff bit after five
// equal bits, from SOF to the end of the CRC sequence, stuff bits counting towards the next run).
int classical_frame_bits(std::uint32_t id, std::uint8_t len, const std::uint8_t* data);

constexpr int classical_frame_bits_worst(int data_bytes) {
  return 47 + 8 * data_bytes + (34 + 8 * data_bytes - 1) / 4;
}

// Valid CAN FD payload sizes: the smallest one of at least `at_least` bytes (-1: none).
constexpr int canfd_payload_bytes(int at_least) {
  constexpr int sizes[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  for (int s : sizes) {
    if (s >= at_least) return s;
  }
  return -1;
}

// An FD frame's bits at each rate (without BRS every bit is nominal: data stays 0).
struct CanFdFrameBits {
  int nominal;  // bits at the arbitration (nominal) rate
  int data;     // bits at the data-phase rate
  constexpr int total() const { return nominal + data; }
  // Transmission time in ns at the protocol's rates.
  constexpr std::int64_t duration_ns() const { return nominal * kNominalBitNs + data * kDataBitNs; }
};

// Bits of the fixed-stuffed stuff count and CRC sequence of an FD frame with `payload_bytes`.
constexpr int canfd_crc_field_bits(int payload_bytes) { return payload_bytes <= 16 ? 27 : 32; }

// Worst-case stuffing, with bit-rate switch.
constexpr CanFdFrameBits canfd_frame_bits_worst(int payload_bytes) {
  const int stuffable = 22 + 8 * payload_bytes;                 // SOF .. end of data
  const int stuff_total = (stuffable - 1) / 4;
  const int stuff_arbitration = (17 - 1) / 4;                   // within SOF .. BRS
  return {17 + stuff_arbitration + 1 + 12,
          5 + 8 * payload_bytes + (stuff_total - stuff_arbitration) + canfd_crc_field_bits(payload_bytes)};
}

// The exact bits of one FD standard data frame with its real dynamic stuff bits (from SOF to the last
// data bit; a stuff bit after BRS is a data-phase bit) and the fixed-stuffed CRC field. `len` must be
// a valid FD length. Without `brs` every bit is nominal.
CanFdFrameBits canfd_frame_bits(std::uint32_t id, std::uint8_t len, const std::uint8_t* data, bool brs);

// The time `frame` takes on the protocol's bus, classical or FD, interframe intermission included,
// exact for its content (ns). Allocates nothing.
std::int64_t frame_time_ns(const CanFrame& frame);

}  // namespace exc::hal
