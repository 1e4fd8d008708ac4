#pragma once
// Checks a `candump -L` capture of the excavator bus frame by frame against the protocol
// (hal/excavator.dbc): known 11-bit data frames on the expected interface, the DBC's frame format
// (CAN FD with bit-rate switch) and length, a valid checksum, and counters in sequence with nothing
// lost. Stricter than the receivers' codec, which tolerates lost frames and does not look at BRS: on
// vcan nothing may be lost.
//   - Cyclic (1 ms) frames carry the cycle mod 16: SYNC's counter steps by exactly one from SYNC to
//     SYNC, and every other cyclic frame carries the counter of the last SYNC before it.
//   - The others (heartbeats, emergencies) count their own sends: +1 per frame of an ID.
// It also measures how each side reacted when the other fell silent (the kill tests), in cycles
// (SYNC frames), so the figure does not depend on how fast the machine running the test is.
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
  // Lines (1-based; 0: none) of the last frame each side sent before any emergency frame of its own.
  std::size_t last_plant_line = 0, last_firmware_line = 0;
  // The first FW_EMERGENCY after the plant's last frame: its line, the SYNCs between the two (the
  // firmware's reaction time in cycles), and its decoded signals "EmergencyStop=1 FaultCode=1".
  std::size_t fw_emergency_line = 0;
  long fw_emergency_cycles = -1;
  std::string fw_emergency_signals;
  // The first PLANT_EMERGENCY after the firmware's last frame (0: none) and its decoded signals.
  std::size_t plant_emergency_line = 0;
  std::string plant_emergency_signals;
  bool ok() const { return errors.empty() && frames > 0; }
};

// interface_name: the interface every line must name (empty: any).
CaptureReport check_capture(std::istream& in, const std::string& interface_name);

}  // namespace exc::vcan
