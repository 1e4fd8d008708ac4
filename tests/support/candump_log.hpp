#pragma once
// The `candump -L` log format, read and written: "(1700000000.123456) vcan0 180#0102030405060708" for a
// classical frame, "(...) vcan0 180##1<hex>" for a CAN FD frame (after "##" one hex digit of FD flags:
// 1 bit-rate switch, 2 error state indicator; then the payload). So a capture of the bus can be
// checked frame by frame against the protocol (IDs, FD flag, length, counters, checksums) and decoded
// by other tools. Test code (the vcan tests' captures): these allocate.
#include <cstdint>
#include <string>

#include "hal/can_frame.hpp"

namespace exc::test {

struct CandumpLine {
  hal::CanFrame frame;           // timestamp_ns: the log's time stamp (CLOCK_REALTIME as candump writes it)
  std::string interface_name;
  bool extended = false;         // 29-bit identifier (never part of this protocol)
  bool remote = false;           // remote request ("R")
  std::uint8_t fd_flags = 0;     // FD frames: the flags digit (frame.brs is its bit 0)
};

// Parses one line. FD payloads must have a valid FD length (0..8, 12, 16, 20, 24, 32, 48, 64 bytes).
// On failure returns false and sets `error` to what is wrong and where (column).
bool parse_candump_line(const std::string& line, CandumpLine& out, std::string& error);

// The line candump -L writes for `frame` received on `interface_name` at `timestamp_ns` (ns since the
// epoch; candump shows microseconds). FD flags: BRS only (a kernel from 6.0 on also marks every FD
// frame it delivers with CANFD_FDF, 4, so candump there writes 5 where this writes 1).
std::string candump_line(const hal::CanFrame& frame, const std::string& interface_name, std::int64_t timestamp_ns);

}  // namespace exc::test
