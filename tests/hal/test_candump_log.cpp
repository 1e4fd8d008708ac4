// Parsing candump -L lines, and a capture of a real exchange checked with the codec.
#include <doctest/doctest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "hal/can_codec.hpp"
#include "hal/can_ports.hpp"
#include "hal/candump_log.hpp"
#include "hal/memory_bus.hpp"

using namespace exc::hal;

TEST_CASE("hal/candump log lines parse into frames") {
  CandumpLine line;
  std::string error;
  REQUIRE(parse_candump_line("(1700000000.123456) vcan0 180#0102030405060708", line, error));
  CHECK(line.interface_name == "vcan0");
  CHECK(line.frame.id == 0x180);
  CHECK(line.frame.dlc == 8);
  CHECK(line.frame.data[0] == 0x01);
  CHECK(line.frame.data[7] == 0x08);
  CHECK(line.frame.timestamp_ns == 1700000000123456000LL);
  CHECK_FALSE(line.extended);

  REQUIRE(parse_candump_line("(0.5) can0 080#", line, error));
  CHECK(line.frame.dlc == 0);
  CHECK(line.frame.timestamp_ns == 500000000);
  REQUIRE(parse_candump_line("(1.000001) vcan0 12345678#AB", line, error));
  CHECK(line.extended);
  REQUIRE(parse_candump_line("(1.000001) vcan0 123#R", line, error));
  CHECK(line.remote);
  REQUIRE(parse_candump_line("(1.000001) vcan0 123##10011223344556677889900", line, error));
  CHECK(line.fd);
  CHECK(line.frame.dlc == 9);  // longer than classical: the codec rejects it as wrong DLC

  for (const char* bad : {"1.0 vcan0 123#00", "(1.0) vcan0 12#00", "(1.0) vcan0 800#00", "(1.0) vcan0 123#0",
                          "(1.0) vcan0 123#001122334455667788", "(x) vcan0 123#00", "(1.0)"}) {
    CAPTURE(bad);
    CHECK_FALSE(parse_candump_line(bad, line, error));
    CHECK(error.find("column") != std::string::npos);
  }
}

TEST_CASE("hal/candump capture of a port exchange validates frame by frame") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  MemoryBusNode* tap = hub.attach(4096);  // a listener, like candump
  FirmwareCanPort firmware(*fw_node);
  PlantCanPort plant(*pl_node);
  for (std::uint64_t k = 0; k < 200; ++k) {
    firmware.send_sync(k);
    std::uint64_t cycle = 0;
    while (plant.poll_sync(cycle)) {
      SensorState s;
      s.cycle = cycle;
      s.position = {0.1, 2.0, 2.5, 1.9};
      s.pressure_valid = {true, true, true};
      plant.write(s);
    }
    SensorState seen;
    firmware.read(seen);
    CommandState c;
    c.cycle = k;
    firmware.write(c);
  }
  // Write the capture as candump -L would, then read it back line by line.
  std::vector<std::string> lines;
  CanFrame f;
  while (tap->receive(f)) {
    char text[96];
    int n = std::snprintf(text, sizeof text, "(%lld.%06lld) vcan0 %03X#", static_cast<long long>(f.timestamp_ns / 1'000'000'000),
                          static_cast<long long>((f.timestamp_ns % 1'000'000'000) / 1000), f.id);
    for (int b = 0; b < f.dlc; ++b) n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), "%02X", f.data[b]);
    lines.emplace_back(text);
  }
  CHECK(lines.size() == 200 * (1 + 4 + 2) + 200);  // SYNC, 4 motion, 2 effort, 1 pressure per cycle
  CanFrameCodec codec;
  for (const auto& text : lines) {
    CandumpLine line;
    std::string error;
    REQUIRE_MESSAGE(parse_candump_line(text, line, error), error);
    const MessageSpec* message = nullptr;
    CHECK(codec.accept(line.frame, message) == RxVerdict::ok);
  }
  CHECK(codec.stats().ok == lines.size());
}
