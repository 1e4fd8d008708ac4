// The two ports over the in-memory bus: complete cycles, values through the codec, emergency and
// heartbeat, a loop that survives dropped, delayed and corrupted frames, and no heap allocation.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "allocation_counter.hpp"
#include "port_fixtures.hpp"
#include "hal/can_ports.hpp"
#include "hal/clock.hpp"
#include "hal/fault_injecting_bus.hpp"
#include "hal/memory_bus.hpp"
#include "hal/socketcan_bus.hpp"

using namespace exc::hal;
using namespace exc::hal::test;

namespace {

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
