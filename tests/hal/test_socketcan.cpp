// SocketCAN on a real vcan0 (MTU 72: CAN FD). This kernel has no CAN, so these run only inside the
// vcan VM (the test `vcan/vcan-vm passes ... and the HAL test` runs this program there and requires
// every case to pass); they are not registered as host tests, where they could only skip.
#include <doctest/doctest.h>

#include <cstdlib>
#include <string>

#include "hal/can_ports.hpp"
#include "hal/clock.hpp"
#include "hal/socketcan_bus.hpp"
#include "port_fixtures.hpp"

using namespace exc::hal;
using namespace exc::hal::test;

TEST_CASE("hal/socketcan on vcan0 broadcasts CAN FD and classical frames between two sockets with filters and timestamps") {
  std::string why;
  REQUIRE_MESSAGE(SocketCanBus::kernel_supports_can(&why), "no SocketCAN in this kernel (" << why << "): run inside tools/vcan-vm");
  std::string error;
  const std::uint32_t a_ids[] = {0x080, 0x181};  // includes what a itself sends
  const std::uint32_t b_ids[] = {0x080, 0x180};
  auto a = SocketCanBus::open("vcan0", a_ids, 2, error);
  REQUIRE_MESSAGE(a != nullptr, "vcan0 not available (" << error << ")");
  auto b = SocketCanBus::open("vcan0", b_ids, 2, error);
  REQUIRE(b != nullptr);
  // A classical frame of 3 bytes, an FD frame of 48 with the bit-rate switch, one of 12 without.
  CanFrame classical = frame_with(0x080, 7);
  classical.len = 3;
  const CanFrame fd48 = frame_with(0x180, 9, true, 48);
  CanFrame fd12 = frame_with(0x180, 11, true, 12);
  fd12.brs = false;
  REQUIRE(a->send(classical));
  REQUIRE(a->send(frame_with(0x555, 1, true, 64)));  // filtered out by the kernel
  REQUIRE(a->send(fd48));
  REQUIRE(a->send(fd12));
  CanFrame got;
  for (const CanFrame* want : {static_cast<const CanFrame*>(&classical), &fd48, static_cast<const CanFrame*>(&fd12)}) {
    REQUIRE(b->wait_readable(100'000'000));
    REQUIRE(b->receive(got));
    CHECK(got.id == want->id);
    CHECK(got.fd == want->fd);
    CHECK(got.brs == want->brs);
    CHECK(got.len == want->len);
    for (int i = 0; i < kCanFdMaxLength; ++i) CHECK(got.data[i] == (i < want->len ? want->data[i] : 0));
    CHECK(got.timestamp_ns > 0);
  }
  CHECK_FALSE(b->wait_readable(20'000'000));  // 0x555 was filtered out
  CHECK_FALSE(a->receive(got));               // a does not hear itself
  CHECK(b->stats().received == 3);
  // A frame no bus can carry is refused before the kernel sees it.
  CanFrame bad = frame_with(0x080, 0, true, 9);
  CHECK_FALSE(a->send(bad));
}

TEST_CASE("hal/socketcan refuses an interface whose MTU cannot carry CAN FD, naming the command that fixes it") {
  std::string why;
  REQUIRE_MESSAGE(SocketCanBus::kernel_supports_can(&why), "no SocketCAN in this kernel (" << why << "): run inside tools/vcan-vm");
  // A vcan of its own with the classical MTU (16), the default of `ip link add ... type vcan`.
  REQUIRE(std::system("ip link show dev vcan9 > /dev/null 2>&1 || ip link add dev vcan9 type vcan") == 0);
  REQUIRE(std::system("ip link set dev vcan9 mtu 16 && ip link set up dev vcan9") == 0);
  std::string error;
  const std::uint32_t ids[] = {0x080};
  auto bus = SocketCanBus::open("vcan9", ids, 1, error);
  CHECK(bus == nullptr);
  MESSAGE(error);
  CHECK(error.find("vcan9") != std::string::npos);
  CHECK(error.find("MTU 16 does not carry CAN FD frames") != std::string::npos);
  CHECK(error.find("ip link set vcan9 mtu 72") != std::string::npos);
  CHECK(std::system("ip link del dev vcan9") == 0);
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
  int complete = 0, mismatches = 0, applied_count = 0;
  SensorState seen;
  CommandState applied;
  // The three command sets in turn, 100 cycles each (within the codec's 5 ms pause rule or beyond
  // it, whatever the VM's speed: a set resuming after 200 cycles has counter step 201 mod 16 = 9,
  // stale, or a paused sender's fresh sequence; both are handled, so only the values are checked).
  const auto mode_of = [](std::uint64_t k) { return static_cast<CommandMode>((k / 100) % 3); };
  for (std::uint64_t k = 0; k < 1200; ++k) {
    REQUIRE(firmware.send_sync(k));
    std::uint64_t cycle = 0;
    REQUIRE(plant.wait_sync(cycle, 100'000'000));
    CHECK(cycle == k);
    if (plant.read(applied)) {
      ++applied_count;
      if (!same_command(applied, command_for(applied.cycle, mode_of(applied.cycle)))) ++mismatches;
    }
    REQUIRE(plant.write(sensors_for(cycle, true)));
    const std::int64_t deadline = exc::hal::monotonic_now_ns() + 100'000'000;
    bool got = false;
    while (!(got = firmware.read(seen)) && exc::hal::monotonic_now_ns() < deadline) fw_bus->wait_readable(1'000'000);
    if (got) {
      ++complete;
      if (!same_sensors(seen, sensors_for(k, true))) ++mismatches;
    }
    REQUIRE(firmware.write(command_for(k, mode_of(k))));
  }
  MESSAGE(applied_count, " command sets applied; plant rx: stale ", plant.rx_stats().stale);
  CHECK(complete == 1200);
  CHECK(mismatches == 0);
  CHECK(applied_count >= 1199 - 3 * 11);  // at worst 3 stale frames at each of the 11 switches
  CHECK(firmware.rx_stats().rejected() == 0);
  CHECK(plant.rx_stats().rejected() == plant.rx_stats().stale);
  CHECK(firmware.last_valid_rx_ns() > 0);
  CHECK(firmware.tx_stats().bus_ns > 0);
  CHECK(firmware.rx_bus_ns() == plant.tx_stats().bus_ns);  // every frame counted at its exact length on both ends
}
