#pragma once
// Checks a `candump -L` capture of the excavator bus frame by frame against the protocol
// (hal/excavator.dbc): known 11-bit data frames on the expected interface, the DBC's DLC, a valid
// checksum, and counters in sequence with nothing lost. Stricter than the receivers' codec, which
// tolerates lost frames: on vcan nothing may be lost.
//   - Cyclic (1 ms) frames carry the cycle mod 16: SYNC's counter steps by exactly one from SYNC to
//     SYNC, and every other cyclic frame carries the counter of the last SYNC before it.
//   - The others (pressures, heartbeats, emergencies) count their own sends: +1 per frame of an ID.
#include <cstddef>
#include <cstdint>
#include <istream>
#include <map>
#include <string>
#include <vector>

namespace exc::vcan {

struct CaptureReport {
  std::size_t frames = 0;                          // lines read (blank lines are skipped)
  std::size_t syncs = 0;
  std::map<std::string, std::size_t> per_message;  // accepted frames by DBC message name
  std::vector<std::string> errors;                 // "line N: what", in capture order
  bool ok() const { return errors.empty() && frames > 0; }
};

// interface_name: the interface every line must name (empty: any).
CaptureReport check_capture(std::istream& in, const std::string& interface_name);

}  // namespace exc::vcan
