// vcan-capture-check: checks a `candump -L` capture of the excavator bus against the protocol, frame
// by frame (see capture_check.hpp). The two-process vcan tests run it on the capture of a run.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

#include "capture_check.hpp"

int main(int argc, char** argv) {
  std::string path, interface_name = "vcan0";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::puts(
          "Usage: vcan-capture-check [--interface NAME] CAPTURE\n"
          "Checks every line of CAPTURE (written by `candump -L`) against hal/excavator.dbc: known\n"
          "identifier, the DBC's DLC, valid CRC-8 checksum, counters in sequence with nothing lost\n"
          "(cyclic frames carry the last SYNC's counter; SYNC, pressures, heartbeats and emergencies\n"
          "step by one), all on interface NAME (default vcan0; \"\" for any).\n"
          "Prints frames per message and every error with its line number. Exit status: 0 when the\n"
          "capture is clean, 1 when a frame is wrong, 2 when CAPTURE cannot be read.");
      return 0;
    }
    if (std::strcmp(argv[i], "--interface") == 0 && i + 1 < argc) {
      interface_name = argv[++i];
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
  const std::size_t shown = report.errors.size() < 50 ? report.errors.size() : 50;
  for (std::size_t i = 0; i < shown; ++i) std::cout << path << ": " << report.errors[i] << "\n";
  if (shown < report.errors.size()) std::cout << "(" << report.errors.size() - shown << " more errors)\n";
  return report.ok() ? 0 : 1;
}
