// The two ports over the in-memory bus: complete cycles, values through the codec, emergency and
// heartbeat, a loop that survives dropped, delayed and corrupted frames, and no heap allocation.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "allocation_counter.hpp"
#include "hal/can_ports.hpp"
#include "hal/clock.hpp"
#include "hal/fault_injecting_bus.hpp"
#include "hal/memory_bus.hpp"
#include "hal/socketcan_bus.hpp"

using namespace exc::hal;

namespace {

// What the plant reports at cycle k, and what the firmware commands at cycle k: smooth functions of
// k inside the signal ranges, so every received value can be checked against the cycle it claims.
SensorState sensors_for(std::uint64_t k, bool hydraulic) {
  SensorState s;
  const double t = 1e-3 * static_cast<double>(k);
  s.cycle = k;
  s.position = {1.2 * std::sin(t), 2.2 + 0.5 * std::sin(0.7 * t), 2.8 + 0.6 * std::cos(0.5 * t), 2.0 + 0.3 * std::sin(t)};
  s.velocity = {1.2 * std::cos(t), 0.35 * std::cos(0.7 * t), -0.3 * std::sin(0.5 * t), 0.3 * std::cos(t)};
  for (int c = 0; c < kCylinderCount; ++c) {
    s.pressure_a[c] = 20e6 + 10e6 * std::sin(t + c);
    s.pressure_b[c] = 15e6 + 5e6 * std::cos(t + c);
    s.pressure_valid[c] = hydraulic;
  }
  s.plant_state = static_cast<std::uint8_t>(k % 7);
  s.plant_faults = static_cast<std::uint8_t>(k % 251);
  return s;
}

CommandState command_for(std::uint64_t k, CommandMode mode) {
  CommandState c;
  const double t = 1e-3 * static_cast<double>(k);
  c.mode = mode;
  c.cycle = k;
  if (mode == CommandMode::effort) {
    c.value = {60000 * std::sin(t), 700000 * std::cos(t), -500000 * std::sin(0.3 * t), 300000 * std::cos(2 * t)};
  } else {
    c.value = {std::sin(t), std::cos(t), -std::sin(0.3 * t), 0.5 * std::cos(2 * t)};
  }
  return c;
}

bool same_motion(const SensorState& got, const SensorState& want) {
  const double tol_position[] = {0.5e-6, 0.5e-5, 0.5e-5, 0.5e-5};
  for (int i = 0; i < kAxisCount; ++i) {
    if (std::fabs(got.position[i] - want.position[i]) > tol_position[i] * 1.001) return false;
    if (std::fabs(got.velocity[i] - want.velocity[i]) > 0.5e-4 * 1.001) return false;
  }
  return got.plant_state == want.plant_state && got.plant_faults == want.plant_faults;
}

bool same_command(const CommandState& got, const CommandState& want) {
  const double tol_effort[] = {2.0, 12.5, 12.5, 12.5};
  for (int i = 0; i < kAxisCount; ++i) {
    const double tol = (want.mode == CommandMode::effort ? tol_effort[i] : 0.00025) * 1.001;
    if (std::fabs(got.value[i] - want.value[i]) > tol) return false;
  }
  return got.mode == want.mode;
}

struct LoopResult {
  int cycles = 0;
  int complete = 0;           // cycles whose full sensor set reached the firmware in time
  int plant_steps = 0;
  int wrong_plant_cycle = 0;  // plant stepped with a cycle ahead of the firmware's or not increasing
  int sensor_mismatch = 0;    // a complete set whose values are not those of its cycle
  int commands_applied = 0;
  int command_mismatch = 0;
  int pressure_mismatch = 0;
  RxStats firmware_rx;
  RxStats plant_rx;
};

// The SYNC-driven cycle of the design, in one thread: firmware SYNC -> plant step and sensors ->
// firmware read and commands. `fw_bus`/`plant_bus` may be fault-injecting decorators.
LoopResult run_loop(CanBus& fw_bus, CanBus& plant_bus, int cycles, CommandMode mode, bool hydraulic) {
  FirmwareCanPort firmware(fw_bus);
  PlantCanPort plant(plant_bus);
  LoopResult r;
  SensorState seen;
  CommandState applied;
  std::uint64_t last_plant_cycle = 0;
  for (int n = 0; n < cycles; ++n) {
    const auto k = static_cast<std::uint64_t>(n) + 5000;  // past the 12-bit wrap region start
    firmware.send_sync(k);
    if (k % kHeartbeatPeriodCycles == 0) firmware.send_heartbeat(3);

    std::uint64_t plant_cycle = 0;
    while (plant.poll_sync(plant_cycle)) {
      ++r.plant_steps;
      // A late (delayed) SYNC may make the plant step an older cycle, never a future or repeated one.
      if (plant_cycle > k || (r.plant_steps > 1 && plant_cycle <= last_plant_cycle)) ++r.wrong_plant_cycle;
      last_plant_cycle = plant_cycle;
      if (plant.read(applied)) {
        ++r.commands_applied;
        if (!same_command(applied, command_for(applied.cycle, mode))) ++r.command_mismatch;
      }
      plant.write(sensors_for(plant_cycle, hydraulic));
      if (plant_cycle % kHeartbeatPeriodCycles == 50) plant.send_heartbeat(sensors_for(plant_cycle, hydraulic).plant_state);
    }

    if (firmware.read(seen)) {
      ++r.complete;
      if (seen.cycle != k || !same_motion(seen, sensors_for(k, hydraulic))) ++r.sensor_mismatch;
    }
    for (int c = 0; c < kCylinderCount; ++c) {
      // Pressures arrive round robin; whatever is held must be within 3 cycles of the current one
      // (a bound on staleness: the functions change by < 30 kPa per 3 ms).
      if (seen.pressure_valid[c] && std::fabs(seen.pressure_a[c] - sensors_for(k, true).pressure_a[c]) > 1e5) {
        ++r.pressure_mismatch;
      }
    }
    firmware.write(command_for(k, mode));
    ++r.cycles;
  }
  r.firmware_rx = firmware.rx_stats();
  r.plant_rx = plant.rx_stats();
  return r;
}

}  // namespace

TEST_CASE("hal/ports carry sensors and effort commands through whole cycles") {
  MemoryBusHub hub;
  MemoryBusNode* fw = hub.attach();
  MemoryBusNode* pl = hub.attach();
  const LoopResult r = run_loop(*fw, *pl, 2000, CommandMode::effort, false);
  CHECK(r.complete == 2000);
  CHECK(r.plant_steps == 2000);
  CHECK(r.wrong_plant_cycle == 0);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.commands_applied == 1999);  // the last cycle's commands wait for the next SYNC
  CHECK(r.command_mismatch == 0);
  CHECK(r.firmware_rx.rejected() == 0);
  CHECK(r.plant_rx.rejected() == 0);
}

TEST_CASE("hal/ports carry valve commands and round-robin pressures") {
  MemoryBusHub hub;
  MemoryBusNode* fw = hub.attach();
  MemoryBusNode* pl = hub.attach();
  const LoopResult r = run_loop(*fw, *pl, 3000, CommandMode::valve, true);
  CHECK(r.complete == 3000);
  CHECK(r.command_mismatch == 0);
  CHECK(r.commands_applied == 2999);
  CHECK(r.pressure_mismatch == 0);
  CHECK(r.firmware_rx.rejected() == 0);
}

TEST_CASE("hal/ports deliver emergency stops and heartbeats both ways") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FirmwareCanPort firmware(*fw_node);
  PlantCanPort plant(*pl_node);
  CHECK(firmware.send_heartbeat(9));
  CHECK(firmware.send_fault(true, 0xBEEF));
  CHECK(firmware.send_sync(1));
  std::uint64_t cycle = 0;
  REQUIRE(plant.poll_sync(cycle));
  CHECK(cycle == 1);
  CommandState command;
  plant.read(command);
  CHECK(command.firmware_mode == 9);
  CHECK(command.emergency_stop);
  CHECK(command.fault_code == 0xBEEF);

  CHECK(plant.send_fault(true, 0x0102));
  CHECK(plant.send_heartbeat(4));
  SensorState state;
  CHECK_FALSE(firmware.read(state));  // no motion frames: not a complete set
  CHECK(state.plant_emergency);
  CHECK(state.plant_fault_code == 0x0102);
  CHECK(state.plant_heartbeat_state == 4);
  CHECK(firmware.last_valid_rx_ns() > 0);
}

TEST_CASE("hal/ports feed the watchdog time only with valid frames") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FirmwareCanPort firmware(*fw_node);
  FaultInjection all_corrupt;
  all_corrupt.corrupt_fraction = 1.0;
  FaultInjectingBus damaged(*pl_node, all_corrupt);
  PlantCanPort plant(damaged);
  SensorState state;
  for (int k = 0; k < 50; ++k) plant.write(sensors_for(static_cast<std::uint64_t>(k), true));
  CHECK_FALSE(firmware.read(state));
  CHECK(firmware.last_valid_rx_ns() == 0);
  CHECK(firmware.rx_stats().corrupt == 50 * 4 + 50);  // 4 motion frames + one pressure frame per cycle
  CHECK(firmware.rx_stats().ok == 0);
  CHECK(state.position[kBoom] == 0.0);  // nothing corrupt reached the state
}

TEST_CASE("hal/ports loop survives dropped frames") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FaultInjection faults;
  faults.drop_fraction = 0.02;
  faults.seed = 7;
  FaultInjectingBus fw_bus(*fw_node, faults);
  faults.seed = 8;
  FaultInjectingBus pl_bus(*pl_node, faults);
  const LoopResult r = run_loop(fw_bus, pl_bus, 20000, CommandMode::effort, true);
  MESSAGE("complete ", r.complete, " of ", r.cycles, ", plant steps ", r.plant_steps, ", commands ", r.commands_applied);
  CHECK(r.wrong_plant_cycle == 0);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  CHECK(r.pressure_mismatch == 0);
  // A cycle completes when SYNC and the 4 motion frames all get through: 0.98^5 ~ 90%.
  CHECK(r.complete > 0.85 * r.cycles);
  CHECK(r.plant_steps > 0.97 * r.cycles);
  CHECK(r.plant_steps < r.cycles);
}

TEST_CASE("hal/ports loop survives corrupted frames and counts every one") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FaultInjection faults;
  faults.corrupt_fraction = 0.02;
  faults.seed = 11;
  FaultInjectingBus fw_bus(*fw_node, faults);
  faults.seed = 12;
  FaultInjectingBus pl_bus(*pl_node, faults);
  const LoopResult r = run_loop(fw_bus, pl_bus, 20000, CommandMode::valve, true);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  CHECK(r.pressure_mismatch == 0);
  CHECK(r.wrong_plant_cycle == 0);
  // A single flipped bit never passes CRC-8: every corrupted frame is counted as corrupt.
  CHECK(r.firmware_rx.corrupt == pl_bus.stats().corrupted);
  CHECK(r.plant_rx.corrupt == fw_bus.stats().corrupted);
  CHECK(r.complete > 0.85 * r.cycles);
}

TEST_CASE("hal/ports loop survives delayed (reordered) frames") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FaultInjection faults;
  faults.delay_fraction = 0.02;
  faults.delay_frames = 3;
  faults.seed = 21;
  FaultInjectingBus fw_bus(*fw_node, faults);
  faults.seed = 22;
  FaultInjectingBus pl_bus(*pl_node, faults);
  const LoopResult r = run_loop(fw_bus, pl_bus, 20000, CommandMode::effort, true);
  MESSAGE("firmware stale ", r.firmware_rx.stale, ", plant stale ", r.plant_rx.stale, ", complete ", r.complete);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  CHECK(r.wrong_plant_cycle == 0);
  CHECK(r.pressure_mismatch == 0);
  CHECK(r.firmware_rx.stale + r.plant_rx.stale > 0);  // late frames were seen and refused
  CHECK(r.complete > 0.85 * r.cycles);
}

TEST_CASE("hal/ports allocate nothing over 100000 cycles on the memory bus") {
  REQUIRE(exc::test::allocation_counting_works());
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FaultInjection faults;
  faults.drop_fraction = 0.01;
  faults.corrupt_fraction = 0.01;
  faults.delay_fraction = 0.01;
  FaultInjectingBus pl_bus(*pl_node, faults);
  LoopResult r;
  std::size_t allocations = 0;
  {
    exc::test::AllocationCounter counter;
    exc::test::EigenNoMallocScope no_eigen_malloc;
    r = run_loop(*fw_node, pl_bus, 100000, CommandMode::effort, true);
    allocations = counter.count();
  }
  CHECK(allocations == 0);
  CHECK(r.cycles == 100000);
  CHECK(r.complete > 90000);
}

TEST_CASE("hal/ports run whole cycles over SocketCAN vcan0") {
  std::string why;
  if (!SocketCanBus::kernel_supports_can(&why)) {
    MESSAGE("SKIPPED: no SocketCAN in this kernel (", why, ")");
    return;
  }
  std::uint32_t fw_ids[kMessageCount];
  std::uint32_t plant_ids[kMessageCount];
  const std::size_t fw_count = receive_ids(Node::firmware, fw_ids, kMessageCount);
  const std::size_t plant_count = receive_ids(Node::plant, plant_ids, kMessageCount);
  std::string error;
  auto fw_bus = SocketCanBus::open("vcan0", fw_ids, fw_count, error);
  if (!fw_bus) {
    MESSAGE("SKIPPED: vcan0 not available (", error, ")");
    return;
  }
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
