// The capture checker used on two-process runs: a clean capture of an exchange between the real
// ports passes; each kind of damage (checksum, length, classical or unswitched frame, unknown ID,
// lost SYNC, lost heartbeat, late frame, other interface, garbage) is found at its line.
#include <doctest/doctest.h>

#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "capture_check.hpp"
#include "hal/can_ports.hpp"
#include "candump_log.hpp"
#include "hal/memory_bus.hpp"

using namespace exc::hal;
using namespace exc::test;

namespace {

std::string line_of(const CanFrame& f, std::int64_t t_ns) { return candump_line(f, "vcan0", t_ns); }

// 250 cycles of the real ports over the memory bus with heartbeats and pressures, as candump -L
// lines in bus order.
std::vector<std::string> clean_capture() {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  MemoryBusNode* tap = hub.attach(1 << 16);
  FirmwareCanPort firmware(*fw_node);
  PlantCanPort plant(*pl_node);
  for (std::uint64_t k = 0; k < 250; ++k) {
    firmware.send_sync(k);
    if (k % kHeartbeatPeriodCycles == 0) firmware.send_heartbeat(2);
    std::uint64_t cycle = 0;
    while (plant.poll_sync(cycle)) {
      SensorState s;
      s.cycle = cycle;
      s.position = {0.1, 2.0, 2.5, 1.9};
      s.pressure_valid = true;
      s.pressure_b = {1e6, 2e6, 3e6, 4e6};
      plant.write(s);
      if (cycle % kHeartbeatPeriodCycles == 50) plant.send_heartbeat(1);
    }
    SensorState seen;
    firmware.read(seen);
    CommandState c;
    c.cycle = k;
    c.value = {1000.0, -2000.0, 3000.0, 400.0};
    firmware.write(c);
  }
  std::vector<std::string> lines;
  CanFrame f;
  std::int64_t t = 1'700'000'000'000'000'000LL;
  while (tap->receive(f)) lines.push_back(line_of(f, t += 1000));
  return lines;
}

exc::vcan::CaptureReport check(const std::vector<std::string>& lines) {
  std::ostringstream text;
  for (const auto& l : lines) text << l << "\n";
  std::istringstream in(text.str());
  return exc::vcan::check_capture(in, "vcan0");
}

std::size_t index_of(const std::vector<std::string>& lines, const std::string& id_hash, int nth) {
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (lines[i].find(" " + id_hash) != std::string::npos && nth-- == 0) return i;
  FAIL("no such frame ", id_hash);
  return 0;
}

// The report has exactly one error, on `line` (1-based), mentioning `what`.
void expect_single_error(const exc::vcan::CaptureReport& r, std::size_t line, const std::string& what) {
  REQUIRE(r.errors.size() >= 1);
  CHECK(r.errors[0].rfind("line " + std::to_string(line) + ": ", 0) == 0);
  CHECK(r.errors[0].find(what) != std::string::npos);
  CHECK_FALSE(r.ok());
}

}  // namespace

TEST_CASE("vcan/capture check passes a clean capture of the real ports") {
  const std::vector<std::string> lines = clean_capture();
  const exc::vcan::CaptureReport r = check(lines);
  INFO("first error: ", (r.errors.empty() ? std::string() : r.errors[0]));
  CHECK(r.ok());
  CHECK(r.frames == lines.size());
  CHECK(r.syncs == 250);
  CHECK(r.per_message.at("SENS_MACHINE") == 250);
  CHECK(r.per_message.at("CMD_EFFORT") == 250);
  CHECK(r.per_message.at("FW_HEARTBEAT") == 3);
  CHECK(r.per_message.at("PLANT_HEARTBEAT") == 2);
}

TEST_CASE("vcan/capture check finds each kind of damage at its line") {
  const std::vector<std::string> clean = clean_capture();

  SUBCASE("a flipped data bit breaks the checksum") {
    std::vector<std::string> lines = clean;
    const std::size_t i = index_of(lines, "180##", 7);
    char& c = lines[i][lines[i].find("##") + 60];  // a pressure byte, deep in the 48
    c = c == '0' ? '1' : '0';
    expect_single_error(check(lines), i + 1, "checksum");
  }
  SUBCASE("a frame of another FD length") {
    std::vector<std::string> lines = clean;
    const std::size_t i = index_of(lines, "100##", 3);
    lines[i] += "00000000";  // 12 -> 16 bytes
    expect_single_error(check(lines), i + 1, "CMD_EFFORT has 16 bytes, the DBC says 12");
  }
  SUBCASE("a classical frame where the DBC has CAN FD") {
    std::vector<std::string> lines = clean;
    const std::size_t i = index_of(lines, "080##", 5);
    lines[i].replace(lines[i].find("##1"), 3, "#");
    expect_single_error(check(lines), i + 1, "SYNC is classical CAN, the DBC says CAN FD with bit-rate switch");
  }
  SUBCASE("an FD frame without the bit-rate switch") {
    std::vector<std::string> lines = clean;
    const std::size_t i = index_of(lines, "180##", 9);
    lines[i].replace(lines[i].find("##1"), 3, "##0");
    expect_single_error(check(lines), i + 1, "SENS_MACHINE is CAN FD without bit-rate switch, the DBC says CAN FD with");
  }
  SUBCASE("an identifier outside the DBC") {
    std::vector<std::string> lines = clean;
    lines.insert(lines.begin() + 40, "(1700000000.000000) vcan0 123##1DEADBEEF");
    expect_single_error(check(lines), 41, "0x123 is not in the DBC");
  }
  SUBCASE("a lost SYNC") {
    std::vector<std::string> lines = clean;
    const std::size_t i = index_of(lines, "080##", 20);
    lines.erase(lines.begin() + static_cast<long>(i));
    // The frames of that cycle now follow the previous SYNC: the first is reported first.
    expect_single_error(check(lines), i + 1, "does not match the last SYNC's");
  }
  SUBCASE("a lost heartbeat") {
    std::vector<std::string> lines = clean;
    lines.erase(lines.begin() + static_cast<long>(index_of(lines, "701##", 1)));
    const std::size_t next = index_of(lines, "701##", 1);
    expect_single_error(check(lines), next + 1, "FW_HEARTBEAT counter 2 after 0");
  }
  SUBCASE("a sensor frame that arrives after the next SYNC") {
    std::vector<std::string> lines = clean;
    const std::size_t i = index_of(lines, "180##", 30);
    const std::size_t sync = index_of(lines, "080##", 31);
    const std::string late = lines[i];
    lines.insert(lines.begin() + static_cast<long>(sync) + 1, late);
    lines.erase(lines.begin() + static_cast<long>(i));
    expect_single_error(check(lines), sync + 1, "SENS_MACHINE counter");
  }
  SUBCASE("a frame on another interface, and a line that is no frame") {
    // Two sensor frames (a lost SYNC or command would bring errors of its own).
    std::vector<std::string> lines = clean;
    const std::size_t a = index_of(lines, "180##", 3), b = index_of(lines, "180##", 6);
    lines[a].replace(lines[a].find("vcan0"), 5, "vcan1");
    lines[b] = "this is not candump output";
    const exc::vcan::CaptureReport r = check(lines);
    REQUIRE(r.errors.size() == 2);
    CHECK(r.errors[0] == "line " + std::to_string(a + 1) + ": interface vcan1, expected vcan0");
    CHECK(r.errors[1].rfind("line " + std::to_string(b + 1) + ": not a candump -L line", 0) == 0);
  }
  SUBCASE("an empty capture") {
    const exc::vcan::CaptureReport r = check({});
    CHECK_FALSE(r.ok());
    CHECK(r.errors.at(0) == "the capture has no frames");
  }
}

TEST_CASE("vcan/capture check counts the cycles from the plant's silence to the firmware's safe stop") {
  // The plant answers cycles 0..99 and then falls silent; the firmware keeps sending SYNC and sends
  // its emergency frame right after SYNC(120): the SYNCs of cycles 100..120, 21 of them, lie between
  // the plant's last frame and the emergency.
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  MemoryBusNode* tap = hub.attach(1 << 16);
  FirmwareCanPort firmware(*fw_node);
  PlantCanPort plant(*pl_node);
  for (std::uint64_t k = 0; k < 140; ++k) {
    firmware.send_sync(k);
    std::uint64_t cycle = 0;
    while (plant.poll_sync(cycle)) {
      if (cycle >= 100) continue;
      SensorState s;
      s.cycle = cycle;
      plant.write(s);
    }
    if (k == 120 || k == 130) firmware.send_fault(true, 1);
  }
  std::vector<std::string> lines;
  CanFrame f;
  std::int64_t t = 1'000'000'000;
  while (tap->receive(f)) lines.push_back(line_of(f, t += 1000));
  const exc::vcan::CaptureReport r = check(lines);
  CHECK(r.ok());
  CHECK(r.last_plant_line == index_of(lines, "180##", 99) + 1);
  CHECK(r.fw_emergency_line == index_of(lines, "010##", 0) + 1);
  CHECK(r.fw_emergency_cycles == 21);
  CHECK(r.fw_emergency_signals == "EmergencyStop=1 FaultCode=1");
  CHECK(r.plant_emergency_line == 0);

  // The reverse: the firmware falls silent after SYNC(139) and the plant sends its emergency.
  plant.send_fault(true, 7);
  while (tap->receive(f)) lines.push_back(line_of(f, t += 1000));
  const exc::vcan::CaptureReport r2 = check(lines);
  CHECK(r2.plant_emergency_line == lines.size());
  CHECK(r2.last_firmware_line == index_of(lines, "080##", 139) + 1);
  CHECK(r2.plant_emergency_signals == "EmergencyStop=1 FaultCode=7");
}
