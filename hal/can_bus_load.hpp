#pragma once
// Worst-case frame lengths, for the bus budget. Standard (11-bit) frames only.
//
// Classical CAN: 47 + 8 n bits for n data bytes without stuffing (SOF, ID, RTR, IDE, r0, DLC, data,
// CRC 15, CRC delimiter, ACK, ACK delimiter, EOF 7, intermission 3). Stuffing applies from SOF to the
// end of the CRC sequence, 34 + 8 n bits, and adds at worst one bit per 4 after the first:
// (34 + 8 n - 1) / 4. This is the figure of can-utils' canframelen (CFL_WORSTCASE) and of the
// kernel's can_frame_bits(); for n = 8 it gives 135 bits.
//
// CAN FD with bit-rate switch: the arbitration part (SOF, ID, RRS, IDE, FDF, res, BRS: 17 bits, at
// most 4 stuff bits), the CRC delimiter, ACK, ACK delimiter, EOF and intermission (1 + 12 bits) run
// at the nominal rate; ESI, DLC (5 bits) and the data with their dynamic stuff bits, then the stuff
// count and CRC with their fixed stuff bits (27 bits for CRC-17 up to 16 bytes, 32 bits for CRC-21
// above) run at the data rate.
#include <cstdint>

namespace exc::hal {

inline constexpr double kClassicalBitRate = 1e6;  // bit/s, the bus the DBC schedule is budgeted for

// CRC-15 of CAN (polynomial 0x4599, initial 0) over `count` bits given MSB first.
std::uint16_t can_crc15(const std::uint8_t* bits, int count);

// The exact length in bits of one classical standard data frame as it goes on the wire: SOF to EOF
// plus the 3-bit intermission, with the stuff bits its content really needs (a stuff bit after five
// equal bits, from SOF to the end of the CRC sequence, stuff bits counting towards the next run).
int classical_frame_bits(std::uint32_t id, std::uint8_t dlc, const std::uint8_t* data);

constexpr int classical_frame_bits_worst(int data_bytes) {
  return 47 + 8 * data_bytes + (34 + 8 * data_bytes - 1) / 4;
}

// Valid CAN FD payload sizes.
constexpr int canfd_payload_bytes(int at_least) {
  constexpr int sizes[] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 12, 16, 20, 24, 32, 48, 64};
  for (int s : sizes) {
    if (s >= at_least) return s;
  }
  return -1;
}

struct CanFdFrameBits {
  int nominal;  // bits at the arbitration (nominal) rate
  int data;     // bits at the data-phase rate
  // Transmission time in ns for the given rates (bit/s).
  constexpr double duration_ns(double nominal_bps, double data_bps) const {
    return 1e9 * (nominal / nominal_bps + data / data_bps);
  }
};

constexpr CanFdFrameBits canfd_frame_bits_worst(int payload_bytes) {
  const int stuffable = 22 + 8 * payload_bytes;                 // SOF .. end of data
  const int stuff_total = (stuffable - 1) / 4;
  const int stuff_arbitration = (17 - 1) / 4;                   // within SOF .. BRS
  const int crc_field = payload_bytes <= 16 ? 27 : 32;          // stuff count + CRC + fixed stuff bits
  return {17 + stuff_arbitration + 1 + 12, 5 + 8 * payload_bytes + (stuff_total - stuff_arbitration) + crc_field};
}

}  // namespace exc::hal
