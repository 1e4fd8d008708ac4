// vcan-capture-check: checks a `candump -L` capture of the excavator bus against the protocol, frame
// by frame (see capture_check.hpp). The two-process vcan tests run it on the capture of a run.
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "capture_check.hpp"

int main(int argc, char** argv) {
  std::string path, interface_name = "vcan0";
  long safe_stop_within = -1;  // --expect-safe-stop-within N (cycles); -1: not asked
  bool expect_plant_hold = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::puts(
          "Usage: vcan-capture-check [--interface NAME] CAPTURE\n"
          "Checks every line of CAPTURE (written by `candump -L`) against hal/excavator.dbc: known\n"
          "identifier, the DBC's frame format (CAN FD with bit-rate switch) and length, valid CRC-8\n"
          "checksum, counters in sequence with nothing lost (cyclic frames carry the last SYNC's\n"
          "counter; SYNC, heartbeats and emergencies step by one), all on interface NAME (default\n"
          "vcan0; \"\" for any).\n"
          "  --expect-safe-stop-within N  also require an FW_EMERGENCY frame at most N cycles (SYNC\n"
          "                               frames) after the plant's last frame (plant killed)\n"
          "  --expect-plant-hold          also require a PLANT_EMERGENCY frame after the firmware's\n"
          "                               last frame (firmware killed)\n"
          "Prints frames per message, the reactions to silence and every error with its line number.\n"
          "Exit status: 0 when the capture is clean (and the expectations hold), 1 otherwise, 2 when\n"
          "the arguments are wrong or CAPTURE cannot be read.");
      return 0;
    }
    if (std::strcmp(argv[i], "--interface") == 0 && i + 1 < argc) {
      interface_name = argv[++i];
    } else if (std::strcmp(argv[i], "--expect-safe-stop-within") == 0 && i + 1 < argc) {
      char* end = nullptr;
      safe_stop_within = std::strtol(argv[++i], &end, 10);
      if (*argv[i] == '\0' || *end != '\0' || safe_stop_within < 0 || safe_stop_within > 1000000) {
        std::fprintf(stderr, "vcan-capture-check: --expect-safe-stop-within '%s': must be cycles in 0..1000000\n", argv[i]);
        return 2;
      }
    } else if (std::strcmp(argv[i], "--expect-plant-hold") == 0) {
      expect_plant_hold = true;
    } else if (argv[i][0] == '-' && argv[i][1] != '\0') {
      std::fprintf(stderr, "vcan-capture-check: unknown option '%s' (see --help)\n", argv[i]);
      return 2;
    } else if (path.empty()) {
      path = argv[i];
    } else {
      std::fprintf(stderr, "vcan-capture-check: only one CAPTURE file, got '%s' and '%s'\n", path.c_str(), argv[i]);
      return 2;
    }
  }
  if (path.empty()) {
    std::fputs("vcan-capture-check: no CAPTURE file given (see --help)\n", stderr);
    return 2;
  }
  std::ifstream in(path);
  if (!in) {
    std::fprintf(stderr, "vcan-capture-check: cannot read %s: %s\n", path.c_str(), std::strerror(errno));
    return 2;
  }
  const exc::vcan::CaptureReport report = exc::vcan::check_capture(in, interface_name);
  std::cout << path << ": " << report.frames << " frames, " << report.syncs << " cycles (SYNC), "
            << report.errors.size() << " errors\n";
  for (const auto& [name, count] : report.per_message) std::cout << "  " << name << ": " << count << "\n";
  bool ok = report.ok();
  if (report.fw_emergency_line > 0) {
    std::cout << path << ": the plant's last frame is line " << report.last_plant_line << "; FW_EMERGENCY ("
              << report.fw_emergency_signals << ") followed " << report.fw_emergency_cycles << " cycles later, line "
              << report.fw_emergency_line << "\n";
  }
  if (report.plant_emergency_line > 0) {
    std::cout << path << ": the firmware's last frame is line " << report.last_firmware_line
              << "; PLANT_EMERGENCY (" << report.plant_emergency_signals << ") followed, line "
              << report.plant_emergency_line << "\n";
  }
  if (safe_stop_within >= 0 && (report.fw_emergency_cycles < 0 || report.fw_emergency_cycles > safe_stop_within)) {
    std::cout << path << ": expected FW_EMERGENCY within " << safe_stop_within << " cycles of the plant's last frame (line "
              << report.last_plant_line << "), "
              << (report.fw_emergency_cycles < 0 ? std::string("found none") : "it came after " + std::to_string(report.fw_emergency_cycles))
              << "\n";
    ok = false;
  }
  if (expect_plant_hold && report.plant_emergency_line == 0) {
    std::cout << path << ": expected PLANT_EMERGENCY after the firmware's last frame (line " << report.last_firmware_line
              << "), found none\n";
    ok = false;
  }
  const std::size_t shown = report.errors.size() < 50 ? report.errors.size() : 50;
  for (std::size_t i = 0; i < shown; ++i) std::cout << path << ": " << report.errors[i] << "\n";
  if (shown < report.errors.size()) std::cout << "(" << report.errors.size() - shown << " more errors)\n";
  return ok ? 0 : 1;
}
