// The two ports over the in-memory bus: complete cycles with every command set and every sensor
// value, emergency and heartbeat, frames of the wrong format refused, a loop that survives dropped,
// delayed and corrupted frames, and no heap allocation.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "app/allocation_counter.hpp"
#include "port_fixtures.hpp"
#include "hal/can_bus_load.hpp"
#include "hal/can_ports.hpp"
#include "hal/clock.hpp"
#include "hal/fault_injecting_bus.hpp"
#include "hal/memory_bus.hpp"

using namespace exc::hal;
using namespace exc::hal::test;

namespace {

struct LoopResult {
  int cycles = 0;
  int complete = 0;           // cycles whose sensor frame reached the firmware in time
  int plant_steps = 0;
  int wrong_plant_cycle = 0;  // plant stepped with a cycle ahead of the firmware's or not increasing
  int sensor_mismatch = 0;    // a complete set whose values are not those of its cycle
  int commands_applied = 0;
  int command_mismatch = 0;
  int applied_by_mode[3] = {};
  RxStats firmware_rx;
  RxStats plant_rx;
};

using ModeOf = CommandMode (*)(std::uint64_t cycle);
CommandMode effort_mode(std::uint64_t) { return CommandMode::effort; }
CommandMode valve_mode(std::uint64_t) { return CommandMode::valve; }
CommandMode pilot_mode(std::uint64_t) { return CommandMode::pilot; }
// Every command set in turn, 700 cycles each (a sender pausing 1.4 s between its runs).
CommandMode rotating_mode(std::uint64_t cycle) {
  constexpr CommandMode kModes[] = {CommandMode::effort, CommandMode::valve, CommandMode::pilot};
  return kModes[(cycle / 700) % 3];
}

// The SYNC-driven cycle of the design, in one thread: firmware SYNC -> plant step and sensors ->
// firmware read and commands. `fw_bus`/`plant_bus` may be fault-injecting decorators. `clock` is the
// hub's: each cycle advances it by 1 ms, so the codec's 5 ms pause rule sees the loop's time, never
// the test machine's (a descheduled test must not turn a late frame into a fresh sequence).
LoopResult run_loop(CanBus& fw_bus, CanBus& plant_bus, int cycles, ModeOf mode_of, bool hydraulic, SimClock& clock) {
  FirmwareCanPort firmware(fw_bus);
  PlantCanPort plant(plant_bus);
  LoopResult r;
  SensorState seen;
  CommandState applied;
  std::uint64_t last_plant_cycle = 0;
  for (int n = 0; n < cycles; ++n) {
    const auto k = static_cast<std::uint64_t>(n) + 5000;  // past the 12-bit wrap region start
    clock.now_ns += kCyclePeriodNs;
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
        ++r.applied_by_mode[static_cast<int>(applied.mode)];
        if (!same_command(applied, command_for(applied.cycle, mode_of(applied.cycle)))) ++r.command_mismatch;
      }
      plant.write(sensors_for(plant_cycle, hydraulic));
      if (plant_cycle % kHeartbeatPeriodCycles == 50) plant.send_heartbeat(sensors_for(plant_cycle, hydraulic).plant_state);
    }

    if (firmware.read(seen)) {
      ++r.complete;
      if (seen.cycle != k || !same_sensors(seen, sensors_for(k, hydraulic))) ++r.sensor_mismatch;
    }
    firmware.write(command_for(k, mode_of(k)));
    ++r.cycles;
  }
  r.firmware_rx = firmware.rx_stats();
  r.plant_rx = plant.rx_stats();
  return r;
}

// Two ports on a memory bus in simulated time, each end sending through its own fault-injecting
// decorator (seeds `faults.seed` and `faults.seed + 1`; no faults by default).
struct Bench {
  SimClock clock;
  MemoryBusHub hub{&SimClock::read, &clock};
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  FaultInjectingBus fw_bus;
  FaultInjectingBus pl_bus;
  explicit Bench(FaultInjection faults = {}) : fw_bus(*fw_node, faults), pl_bus(*pl_node, next_seed(faults)) {}
  LoopResult run(int cycles, ModeOf mode_of, bool hydraulic) {
    return run_loop(fw_bus, pl_bus, cycles, mode_of, hydraulic, clock);
  }
  static FaultInjection next_seed(FaultInjection faults) {
    ++faults.seed;
    return faults;
  }
};

// A loop on a clean bus: every cycle complete with its own values, every command applied but the last
// (it waits for the next SYNC), nothing refused; with `mode`, every command applied as that set.
void check_clean(const LoopResult& r, int cycles, const CommandMode* mode = nullptr) {
  if (mode != nullptr) CHECK(r.applied_by_mode[static_cast<int>(*mode)] == cycles - 1);
  CHECK(r.complete == cycles);
  CHECK(r.plant_steps == cycles);
  CHECK(r.wrong_plant_cycle == 0);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.commands_applied == cycles - 1);
  CHECK(r.command_mismatch == 0);
  CHECK(r.firmware_rx.rejected() == 0);
  CHECK(r.plant_rx.rejected() == 0);
}

}  // namespace

TEST_CASE("hal/ports carry sensors and effort commands through whole cycles") {
  constexpr CommandMode kEffort = CommandMode::effort;
  check_clean(Bench().run(2000, effort_mode, false), 2000, &kEffort);
}

TEST_CASE("hal/ports carry valve commands, and every chamber and pump pressure every cycle") {
  // same_sensors: all 8 chamber and both pump pressures of that cycle, every cycle.
  constexpr CommandMode kValve = CommandMode::valve;
  check_clean(Bench().run(3000, valve_mode, true), 3000, &kValve);
}

TEST_CASE("hal/ports carry pilot pressures on both spool ends of every axis") {
  constexpr CommandMode kPilot = CommandMode::pilot;
  check_clean(Bench().run(3000, pilot_mode, true), 3000, &kPilot);
}

TEST_CASE("hal/ports switch between the three command sets, each latched as the set it is") {
  Bench bench;
  const LoopResult r = bench.run(4200, rotating_mode, true);
  check_clean(r, 4200);  // a set resuming after 1.4 s starts a new counter sequence: nothing refused
  // Cycles 5000..9199, mode (k / 700) % 3: valve 5000..5599, 7000..7699, 9100..9199 (the last one's
  // command is never applied), pilot 5600..6299, 7700..8399, effort 6300..6999, 8400..9099.
  CHECK(r.applied_by_mode[static_cast<int>(CommandMode::effort)] == 1400);
  CHECK(r.applied_by_mode[static_cast<int>(CommandMode::valve)] == 1399);
  CHECK(r.applied_by_mode[static_cast<int>(CommandMode::pilot)] == 1400);
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
  CHECK_FALSE(firmware.read(state));  // no sensor frame: not a complete set
  CHECK(state.plant_emergency);
  CHECK(state.plant_fault_code == 0x0102);
  CHECK(state.plant_heartbeat_state == 4);
  CHECK(firmware.last_valid_rx_ns() > 0);
}

TEST_CASE("hal/ports carry an operator's SUPERVISOR commands to the firmware only, each frame once") {
  MemoryBusHub hub;
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  MemoryBusNode* op_node = hub.attach();
  FirmwareCanPort firmware(*fw_node);
  PlantCanPort plant(*pl_node);
  OperatorCanPort station(*op_node);
  const auto bit = [](SupervisorCommand c) { return static_cast<std::uint8_t>(1u << static_cast<unsigned>(c)); };
  CHECK(station.send(SupervisorCommand::acknowledge));
  CHECK(station.send(SupervisorCommand::start));
  SensorState state;
  firmware.read(state);
  CHECK(state.supervisor_pending == (bit(SupervisorCommand::acknowledge) | bit(SupervisorCommand::start)));
  state.supervisor_pending = 0;  // taken
  firmware.read(state);
  CHECK(state.supervisor_pending == 0);  // nothing new: nothing pending
  // The same frame again (a repeat on the bus) is rejected by its counter, so it commands nothing.
  CanFrame stop;
  const double value[] = {static_cast<double>(SupervisorCommand::stop)};
  encode_message(*find_message(can_id::supervisor), station.next_counter(), value, stop);
  REQUIRE(op_node->send(stop));
  REQUIRE(op_node->send(stop));
  firmware.read(state);
  CHECK(state.supervisor_pending == bit(SupervisorCommand::stop));
  CHECK(firmware.rx_stats().repeated == 1);
  // The plant passes it: no command set, no SYNC, nothing latched.
  std::uint64_t cycle = 0;
  CHECK_FALSE(plant.poll_sync(cycle));
  CommandState command;
  CHECK_FALSE(plant.read(command));
  CHECK_FALSE(command.valid);
  // On SocketCAN the plant's kernel filter keeps SUPERVISOR out; the firmware's lets it in.
  std::uint32_t ids[kMessageCount];
  const auto listens = [&](Node node) {
    const std::size_t n = receive_ids(node, ids, kMessageCount);
    for (std::size_t i = 0; i < n; ++i) {
      if (ids[i] == can_id::supervisor) return true;
    }
    return false;
  };
  CHECK(listens(Node::firmware));
  CHECK_FALSE(listens(Node::plant));
}

TEST_CASE("hal/ports refuse a classical frame, or an FD frame of another length, where the DBC has an FD frame") {
  Bench bench;
  MemoryBusNode* foreign = bench.hub.attach();
  PlantCanPort plant(bench.pl_bus);
  // A valid SYNC, then the same content as a classical frame (a node that does not speak FD), then
  // as an FD frame of 8 bytes: both refused and counted, nothing steps the plant.
  CanFrame sync;
  const double cycle[] = {7};
  encode_message(*find_message(can_id::sync), 7, cycle, sync);
  CanFrame classical = sync;
  classical.fd = classical.brs = false;
  CanFrame longer = sync;
  longer.len = 8;
  REQUIRE(foreign->send(classical));
  REQUIRE(foreign->send(longer));
  std::uint64_t k = 0;
  CHECK_FALSE(plant.poll_sync(k));
  CHECK(plant.rx_stats().wrong_format == 2);
  CHECK(plant.last_valid_rx_ns() == 0);
  REQUIRE(foreign->send(sync));
  CHECK(plant.poll_sync(k));
  CHECK(k == 7);
  CHECK(plant.rx_stats().ok == 1);
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
  CHECK(firmware.rx_stats().corrupt == 50);  // one SENS_MACHINE per cycle
  CHECK(firmware.rx_stats().ok == 0);
  CHECK(state.position[kBoom] == 0.0);  // nothing corrupt reached the state
  CHECK(state.pressure_a[kBoom] == 0.0);
}

TEST_CASE("hal/ports loop survives dropped frames") {
  FaultInjection faults;
  faults.drop_fraction = 0.02;
  faults.seed = 7;
  Bench bench(faults);
  const LoopResult r = bench.run(20000, effort_mode, true);
  MESSAGE("complete ", r.complete, " of ", r.cycles, ", plant steps ", r.plant_steps, ", commands ", r.commands_applied);
  CHECK(r.wrong_plant_cycle == 0);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  // A cycle completes when SYNC and the sensor frame both get through: 0.98^2 ~ 96%.
  CHECK(r.complete > 0.94 * r.cycles);
  CHECK(r.plant_steps > 0.97 * r.cycles);
  CHECK(r.plant_steps < r.cycles);
}

TEST_CASE("hal/ports loop survives corrupted frames and counts every one") {
  FaultInjection faults;
  faults.corrupt_fraction = 0.02;
  faults.seed = 11;
  Bench bench(faults);
  const LoopResult r = bench.run(20000, pilot_mode, true);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  CHECK(r.wrong_plant_cycle == 0);
  // A single flipped bit never passes CRC-8, in 48 bytes as in 4: every corrupted frame is counted.
  CHECK(r.firmware_rx.corrupt == bench.pl_bus.stats().corrupted);
  CHECK(r.plant_rx.corrupt == bench.fw_bus.stats().corrupted);
  CHECK(r.complete > 0.94 * r.cycles);
}

TEST_CASE("hal/ports time every frame received at its exact on-wire length, one corrupted on the way as it arrived") {
  // The sender times each frame once and the frame carries it; a bus that flips a bit must make the
  // receiver time what it got (another stuffing). A third node sees every frame as the plant does and
  // times each one afresh: the plant's count must be its sum.
  SimClock clock;
  MemoryBusHub hub{&SimClock::read, &clock};
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  MemoryBusNode* observer = hub.attach();
  FaultInjection faults;
  faults.corrupt_fraction = 0.3;
  faults.seed = 5;
  FaultInjectingBus fw_bus(*fw_node, faults);
  FirmwareCanPort firmware(fw_bus);
  PlantCanPort plant(*pl_node);
  std::uint64_t observed_ns = 0;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    clock.now_ns += kCyclePeriodNs;
    firmware.send_sync(k);
    firmware.write(command_for(k, CommandMode::pilot));
    std::uint64_t cycle = 0;
    while (plant.poll_sync(cycle)) {
    }
    CanFrame frame;
    while (observer->receive(frame)) observed_ns += static_cast<std::uint64_t>(frame_time_ns(frame));
  }
  REQUIRE(fw_bus.stats().corrupted > 100);
  // The test's power: the corrupted frames' stuffing changed the bus time, so a receiver that took the
  // sender's time for them would count another sum.
  REQUIRE(observed_ns != firmware.tx_stats().bus_ns);
  CHECK(plant.rx_bus_ns() == observed_ns);
  CHECK(plant.rx_stats().corrupt == fw_bus.stats().corrupted);
}

TEST_CASE("hal/ports loop survives delayed (reordered) frames") {
  FaultInjection faults;
  faults.delay_fraction = 0.02;
  faults.delay_frames = 3;
  faults.seed = 21;
  Bench bench(faults);
  const LoopResult r = bench.run(20000, valve_mode, true);
  MESSAGE("firmware stale ", r.firmware_rx.stale, ", plant stale ", r.plant_rx.stale, ", complete ", r.complete);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  CHECK(r.wrong_plant_cycle == 0);
  CHECK(r.firmware_rx.stale + r.plant_rx.stale > 0);  // late frames were seen and refused
  CHECK(r.complete > 0.94 * r.cycles);
}

TEST_CASE("hal/ports allocate nothing over 100000 cycles of every frame on the memory bus") {
  REQUIRE(exc::app::allocation_counting_works());
  FaultInjection faults;
  faults.drop_fraction = 0.01;
  faults.corrupt_fraction = 0.01;
  faults.delay_fraction = 0.01;
  Bench bench(faults);
  LoopResult r;
  std::size_t allocations = 0;
  {
    exc::app::AllocationCounter counter;
    exc::app::EigenNoMallocScope no_eigen_malloc;
    // SENS_MACHINE with all pressures, the three command sets in turn, heartbeats, faults both ways.
    r = bench.run(100000, rotating_mode, true);
    allocations = counter.count();
  }
  CHECK(allocations == 0);
  CHECK(r.cycles == 100000);
  CHECK(r.complete > 93000);
  CHECK(r.sensor_mismatch == 0);
  CHECK(r.command_mismatch == 0);
  for (int mode = 0; mode < 3; ++mode) CHECK(r.applied_by_mode[mode] > 31000);  // a third each, less the faults
}
