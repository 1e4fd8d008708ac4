#pragma once
// Reading `candump -L` log lines ("(1700000000.123456) vcan0 180#0102030405060708"), so a capture
// of the bus can be checked frame by frame against the protocol (IDs, DLC, counters, checksums).
#include <cstdint>
#include <string>

#include "hal/can_frame.hpp"

namespace exc::hal {

struct CandumpLine {
  CanFrame frame;                // timestamp_ns: the log's time stamp (CLOCK_REALTIME as candump writes it)
  std::string interface_name;
  bool extended = false;         // 29-bit identifier (never part of this protocol)
  bool remote = false;           // remote request ("R")
  bool fd = false;               // CAN FD ("##"); only the first 8 data bytes are kept
};

// Parses one line. A payload longer than 8 bytes (CAN FD) gives dlc 9, which no protocol frame has.
// On failure returns false and sets `error` to what is wrong and where (column).
bool parse_candump_line(const std::string& line, CandumpLine& out, std::string& error);

}  // namespace exc::hal
