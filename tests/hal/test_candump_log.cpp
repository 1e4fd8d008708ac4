// The candump -L format, read and written (classical and CAN FD lines), and a capture of a real
// exchange written in that format and checked with the codec.
#include <doctest/doctest.h>

#include <string>
#include <vector>

#include "hal/can_codec.hpp"
#include "hal/can_ports.hpp"
#include "candump_log.hpp"
#include "hal/memory_bus.hpp"

using namespace exc::hal;
using namespace exc::test;

TEST_CASE("hal/candump log lines parse into frames") {
  CandumpLine line;
  std::string error;
  REQUIRE(parse_candump_line("(1700000000.123456) vcan0 180#0102030405060708", line, error));
  CHECK(line.interface_name == "vcan0");
  CHECK(line.frame.id == 0x180);
  CHECK(line.frame.len == 8);
  CHECK_FALSE(line.frame.fd);
  CHECK(line.frame.data[0] == 0x01);
  CHECK(line.frame.data[7] == 0x08);
  CHECK(line.frame.timestamp_ns == 1700000000123456000LL);
  CHECK_FALSE(line.extended);

  REQUIRE(parse_candump_line("(0.5) can0 080#", line, error));
  CHECK(line.frame.len == 0);
  CHECK(line.frame.timestamp_ns == 500000000);
  REQUIRE(parse_candump_line("(1.000001) vcan0 12345678#AB", line, error));
  CHECK(line.extended);
  REQUIRE(parse_candump_line("(1.000001) vcan0 123#R", line, error));
  CHECK(line.remote);

  // CAN FD: "##", one hex digit of flags (1: bit-rate switch, 2: error state indicator), the payload.
  REQUIRE(parse_candump_line("(1.000001) vcan0 123##1001122334455667788990011", line, error));
  CHECK(line.frame.fd);
  CHECK(line.frame.brs);
  CHECK(line.fd_flags == 1);
  CHECK(line.frame.len == 12);
  CHECK(line.frame.data[11] == 0x11);
  REQUIRE(parse_candump_line("(1.000001) vcan0 123##2AABB", line, error));
  CHECK(line.frame.fd);
  CHECK_FALSE(line.frame.brs);
  CHECK(line.fd_flags == 2);
  CHECK(line.frame.len == 2);
  std::string sixty_four = "(1.0) vcan0 7FF##3";
  for (int i = 0; i < 64; ++i) sixty_four += "A5";
  REQUIRE(parse_candump_line(sixty_four, line, error));
  CHECK(line.frame.len == 64);
  CHECK(line.frame.data[63] == 0xA5);

  for (const char* bad : {"1.0 vcan0 123#00", "(1.0) vcan0 12#00", "(1.0) vcan0 800#00", "(1.0) vcan0 123#0",
                          "(1.0) vcan0 123#001122334455667788", "(x) vcan0 123#00", "(1.0)",
                          "(1.0) vcan0 123##", "(1.0) vcan0 123##G00", "(1.0) vcan0 123##1001122334455667788"}) {
    CAPTURE(bad);
    CHECK_FALSE(parse_candump_line(bad, line, error));
    CHECK(error.find("column") != std::string::npos);
  }
  // A time stamp whose nanoseconds would not fit an int64 (the digits overflowed, signed: undefined).
  CHECK(parse_candump_line("(9000000000.999999) vcan0 123#00", line, error));
  CHECK(line.frame.timestamp_ns == 9000000000999999000LL);
  for (const char* far : {"(9000000001.0) vcan0 123#00", "(99999999999999999999999.0) vcan0 123#00"}) {
    CAPTURE(far);
    CHECK_FALSE(parse_candump_line(far, line, error));
    CHECK(error == "time stamp beyond 9e9 s at column 2");
  }
  // Nine bytes is no CAN FD length.
  CHECK_FALSE(parse_candump_line("(1.0) vcan0 123##1001122334455667788", line, error));
  CHECK(error.find("9 data bytes is not a CAN FD length") != std::string::npos);
}

TEST_CASE("hal/candump lines written for classical and FD frames are what candump writes, and read back") {
  CanFrame f;
  f.id = 0x80;
  f.len = 3;
  f.data[0] = 0x0A;
  f.data[1] = 0xB0;
  f.data[2] = 0xFF;
  CHECK(candump_line(f, "vcan0", 1'700'000'000'123'456'789LL) == "(1700000000.123456) vcan0 080#0AB0FF");
  f.fd = true;
  f.brs = true;
  CHECK(candump_line(f, "can1", 5'000'001'000LL) == "(5.000001) can1 080##10AB0FF");
  f.brs = false;
  CHECK(candump_line(f, "can1", 0) == "(0.000000) can1 080##00AB0FF");
  f.brs = true;
  f.len = 48;
  for (int i = 0; i < 48; ++i) f.data[i] = static_cast<std::uint8_t>(7 * i);
  CandumpLine back;
  std::string error;
  REQUIRE(parse_candump_line(candump_line(f, "vcan0", 42'000), back, error));
  CHECK(back.frame.id == f.id);
  CHECK(back.frame.len == 48);
  CHECK(back.frame.fd);
  CHECK(back.frame.brs);
  for (int i = 0; i < 48; ++i) CHECK(back.frame.data[i] == f.data[i]);
  CHECK(back.frame.timestamp_ns == 42'000);
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
      s.pressure_valid = true;
      s.pressure_a = {10e6, 20e6, 30e6, 5e6};
      plant.write(s);
    }
    SensorState seen;
    firmware.read(seen);
    CommandState c;
    c.cycle = k;
    c.mode = static_cast<CommandMode>(k % 3);
    firmware.write(c);
  }
  // Write the capture as candump -L would, then read it back line by line.
  std::vector<std::string> lines;
  CanFrame f;
  while (tap->receive(f)) lines.push_back(candump_line(f, "vcan0", f.timestamp_ns));
  CHECK(lines.size() == 200 * 3);  // SYNC, SENS_MACHINE, one command frame per cycle
  CanFrameCodec codec;
  for (const auto& text : lines) {
    CandumpLine line;
    std::string error;
    REQUIRE_MESSAGE(parse_candump_line(text, line, error), error);
    CHECK(line.frame.fd);
    CHECK(line.frame.brs);
    const MessageSpec* message = nullptr;
    CHECK(codec.accept(line.frame, message) == RxVerdict::ok);
  }
  CHECK(codec.stats().ok == lines.size());
}
