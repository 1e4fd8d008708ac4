// SocketCAN on a real vcan0. This kernel has no CAN, so these run only inside the vcan VM (the test
// `vcan/vcan-vm passes ... and the HAL test` runs this program there and requires both cases to pass);
// they are not registered as host tests, where they could only skip.
#include <doctest/doctest.h>

#include <string>

#include "hal/can_ports.hpp"
#include "hal/clock.hpp"
#include "hal/socketcan_bus.hpp"
#include "port_fixtures.hpp"

using namespace exc::hal;
using namespace exc::hal::test;

TEST_CASE("hal/socketcan on vcan0 broadcasts between two sockets with filters and timestamps") {
  std::string why;
  REQUIRE_MESSAGE(SocketCanBus::kernel_supports_can(&why), "no SocketCAN in this kernel (" << why << "): run inside tools/vcan-vm");
  std::string error;
  const std::uint32_t a_ids[] = {0x080, 0x181};  // includes what a itself sends
  const std::uint32_t b_ids[] = {0x080};
  auto a = SocketCanBus::open("vcan0", a_ids, 2, error);
  REQUIRE_MESSAGE(a != nullptr, "vcan0 not available (" << error << ")");
  auto b = SocketCanBus::open("vcan0", b_ids, 1, error);
  REQUIRE(b != nullptr);
  CanFrame f = frame_with(0x080, 7);
  f.dlc = 3;
  REQUIRE(a->send(f));
  CanFrame filtered = frame_with(0x555, 1);
  REQUIRE(a->send(filtered));
  REQUIRE(b->wait_readable(100'000'000));
  CanFrame got;
  REQUIRE(b->receive(got));
  CHECK(got.id == 0x080);
  CHECK(got.dlc == 3);
  CHECK(got.data[0] == 7);
  CHECK(got.timestamp_ns > 0);
  CHECK_FALSE(b->wait_readable(20'000'000));  // 0x555 is filtered out by the kernel
  CHECK_FALSE(a->receive(got));               // a does not hear itself
}

TEST_CASE("hal/ports run whole cycles over SocketCAN vcan0") {
  std::string why;
  REQUIRE_MESSAGE(SocketCanBus::kernel_supports_can(&why), "no SocketCAN in this kernel (" << why << "): run inside tools/vcan-vm");
  std::uint32_t fw_ids[kMessageCount];
  std::uint32_t plant_ids[kMessageCount];
  const std::size_t fw_count = receive_ids(Node::firmware, fw_ids, kMessageCount);
  const std::size_t plant_count = receive_ids(Node::plant, plant_ids, kMessageCount);
  std::string error;
  auto fw_bus = SocketCanBus::open("vcan0", fw_ids, fw_count, error);
  REQUIRE_MESSAGE(fw_bus != nullptr, "vcan0 not available (" << error << ")");
  auto plant_bus = SocketCanBus::open("vcan0", plant_ids, plant_count, error);
  REQUIRE(plant_bus != nullptr);
  FirmwareCanPort firmware(*fw_bus);
  PlantCanPort plant(*plant_bus);
  int complete = 0, mismatches = 0;
  SensorState seen;
  CommandState applied;
  for (std::uint64_t k = 0; k < 1000; ++k) {
    REQUIRE(firmware.send_sync(k));
    std::uint64_t cycle = 0;
    REQUIRE(plant.wait_sync(cycle, 100'000'000));
    CHECK(cycle == k);
    if (plant.read(applied) && !same_command(applied, command_for(applied.cycle, CommandMode::effort))) ++mismatches;
    REQUIRE(plant.write(sensors_for(cycle, true)));
    const std::int64_t deadline = exc::hal::monotonic_now_ns() + 100'000'000;
    bool got = false;
    while (!(got = firmware.read(seen)) && exc::hal::monotonic_now_ns() < deadline) fw_bus->wait_readable(1'000'000);
    if (got) {
      ++complete;
      if (!same_motion(seen, sensors_for(k, true))) ++mismatches;
    }
    REQUIRE(firmware.write(command_for(k, CommandMode::effort)));
  }
  CHECK(complete == 1000);
  CHECK(mismatches == 0);
  CHECK(firmware.rx_stats().rejected() == 0);
  CHECK(plant.rx_stats().rejected() == 0);
  CHECK(firmware.last_valid_rx_ns() > 0);
}
