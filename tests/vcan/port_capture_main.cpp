// vcan-port-capture: runs the firmware and plant ports over the in-memory bus with a listener, as
// candump listens on vcan0, and writes what went over the bus as a `candump -L` capture together with
// what the sender put in each frame (JSON lines, in capture order: {"line", "message", "signals":
// {name: physical value}}), named by DBC signal here, independently of the ports' own mapping. An
// independent DBC decoder (tests/vcan/canmatrix_decode.py) then decodes the capture and compares.
// Every frame kind goes out: SYNC, the three command sets in turn, SENS_MACHINE with every pressure
// and spool position, both heartbeats, both emergency frames and the operator station's SUPERVISOR
// (every command).
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "hal/can_ports.hpp"
#include "candump_log.hpp"
#include "hal/memory_bus.hpp"

using namespace exc::hal;
using namespace exc::test;

namespace {

struct SimClock {
  std::int64_t now_ns = 1'700'000'000'000'000'000LL;
  static std::int64_t read(void* self) { return static_cast<SimClock*>(self)->now_ns; }
};

using Signals = std::vector<std::pair<const char*, double>>;

class Recorder {
 public:
  Recorder(MemoryBusNode& tap, std::ofstream& capture, std::ofstream& sent) : tap_(tap), capture_(capture), sent_(sent) {}
  // Every port call sends exactly one frame: take it off the tap and write it with what was sent.
  bool record(const char* message, const Signals& signals) {
    CanFrame frame;
    if (!tap_.receive(frame) || tap_.pending() != 0) {
      std::fprintf(stderr, "vcan-port-capture: %s: expected exactly one frame on the bus\n", message);
      return false;
    }
    capture_ << candump_line(frame, "vcan0", frame.timestamp_ns) << "\n";
    ++line_;
    sent_ << "{\"line\": " << line_ << ", \"message\": \"" << message << "\", \"signals\": {";
    for (std::size_t i = 0; i < signals.size(); ++i) {
      char value[40];
      std::snprintf(value, sizeof value, "%.17g", signals[i].second);
      sent_ << (i ? ", " : "") << "\"" << signals[i].first << "\": " << value;
    }
    sent_ << "}}\n";
    return true;
  }

 private:
  MemoryBusNode& tap_;
  std::ofstream& capture_;
  std::ofstream& sent_;
  long line_ = 0;
};

SensorState sensors_at(std::uint64_t k) {
  SensorState s;
  const double t = 1e-3 * static_cast<double>(k);
  s.cycle = k;
  s.position = {-2.5 + 0.9 * std::sin(t), 1.8 + 0.6 * std::sin(0.7 * t), 2.4 + 0.5 * std::cos(0.5 * t), 1.6 + 0.4 * std::sin(t)};
  s.velocity = {0.8 * std::cos(t), -0.3 * std::cos(0.7 * t), 0.25 * std::sin(0.5 * t), -0.4 * std::cos(t)};
  for (int a = 0; a < kAxisCount; ++a) {
    s.pressure_a[a] = 18e6 + 15e6 * std::sin(1.3 * t + a);
    s.pressure_b[a] = 5e6 + 4e6 * std::cos(0.9 * t + a);
  }
  s.pump_pressure = {30e6 + 4e6 * std::sin(2 * t), 29e6 + 4e6 * std::cos(2 * t)};
  for (int a = 0; a < kAxisCount; ++a) s.spool[a] = 1.02 * std::sin(1.7 * t + a);  // past the stroke's ends, both ways
  s.pressure_valid = (k / 50) % 2 == 0;
  s.plant_state = static_cast<std::uint8_t>(k % 9);
  s.plant_faults = static_cast<std::uint8_t>(k % 200);
  return s;
}

Signals sensor_signals(const SensorState& s) {
  return {{"PlantState", s.plant_state},       {"SwingAngle", s.position[kSwing]},   {"SwingRate", s.velocity[kSwing]},
          {"PlantFaults", s.plant_faults},     {"BoomLength", s.position[kBoom]},    {"BoomRate", s.velocity[kBoom]},
          {"ArmLength", s.position[kArm]},     {"ArmRate", s.velocity[kArm]},        {"BucketLength", s.position[kBucket]},
          {"BucketRate", s.velocity[kBucket]}, {"PressureValid", s.pressure_valid ? 1.0 : 0.0},
          {"SwingPressureA", s.pressure_a[kSwing]},   {"SwingPressureB", s.pressure_b[kSwing]},
          {"BoomPressureA", s.pressure_a[kBoom]},     {"BoomPressureB", s.pressure_b[kBoom]},
          {"ArmPressureA", s.pressure_a[kArm]},       {"ArmPressureB", s.pressure_b[kArm]},
          {"BucketPressureA", s.pressure_a[kBucket]}, {"BucketPressureB", s.pressure_b[kBucket]},
          {"Pump1Pressure", s.pump_pressure[0]},      {"Pump2Pressure", s.pump_pressure[1]},
          {"SwingSpool", s.spool[kSwing]},            {"BoomSpool", s.spool[kBoom]},
          {"ArmSpool", s.spool[kArm]},                {"BucketSpool", s.spool[kBucket]}};
}

CommandState command_at(std::uint64_t k, const char*& message, Signals& signals) {
  CommandState c;
  const double t = 1e-3 * static_cast<double>(k);
  c.cycle = k;
  c.mode = static_cast<CommandMode>((k / 40) % 3);
  switch (c.mode) {
    case CommandMode::effort:
      c.value = {50000 * std::sin(t), -600000 * std::cos(t), 400000 * std::sin(0.3 * t), -200000 * std::cos(2 * t)};
      message = "CMD_EFFORT";
      signals = {{"SwingTorque", c.value[0]}, {"BoomForce", c.value[1]}, {"ArmForce", c.value[2]}, {"BucketForce", c.value[3]}};
      break;
    case CommandMode::valve:
      c.value = {0.9 * std::sin(t), -std::cos(t), 0.5 * std::sin(3 * t), -0.25};
      message = "CMD_VALVE";
      signals = {{"SwingValve", c.value[0]}, {"BoomValve", c.value[1]}, {"ArmValve", c.value[2]}, {"BucketValve", c.value[3]}};
      break;
    case CommandMode::pilot:
      for (int a = 0; a < kAxisCount; ++a) {
        c.pilot_a[a] = 2.5e6 + 2.4e6 * std::sin(t + a);
        c.pilot_b[a] = 2.5e6 - 2.4e6 * std::sin(t + a);
      }
      message = "CMD_PILOT";
      signals = {{"SwingPilotA", c.pilot_a[0]}, {"SwingPilotB", c.pilot_b[0]}, {"BoomPilotA", c.pilot_a[1]},
                 {"BoomPilotB", c.pilot_b[1]},  {"ArmPilotA", c.pilot_a[2]},   {"ArmPilotB", c.pilot_b[2]},
                 {"BucketPilotA", c.pilot_a[3]}, {"BucketPilotB", c.pilot_b[3]}};
      break;
  }
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4 || std::strcmp(argv[1], "--help") == 0) {
    std::puts(
        "Usage: vcan-port-capture CYCLES CAPTURE SENT\n"
        "Runs the firmware and plant ports over the in-memory bus for CYCLES cycles (every frame kind)\n"
        "and writes the bus as a candump -L capture (CAPTURE) and what was sent in each frame as JSON\n"
        "lines (SENT), for tests/vcan/canmatrix_decode.py --expect SENT CAPTURE.");
    return argc == 2 ? 0 : 2;
  }
  const long cycles = std::strtol(argv[1], nullptr, 10);
  if (cycles < 1 || cycles > 1000000) {
    std::fprintf(stderr, "vcan-port-capture: CYCLES '%s': must be in 1..1000000\n", argv[1]);
    return 2;
  }
  std::ofstream capture(argv[2]), sent(argv[3]);
  if (!capture || !sent) {
    std::fprintf(stderr, "vcan-port-capture: cannot write %s or %s: %s\n", argv[2], argv[3], std::strerror(errno));
    return 2;
  }
  SimClock clock;
  MemoryBusHub hub(&SimClock::read, &clock);
  MemoryBusNode* fw_node = hub.attach();
  MemoryBusNode* pl_node = hub.attach();
  MemoryBusNode* op_node = hub.attach();
  MemoryBusNode* tap = hub.attach(16);
  FirmwareCanPort firmware(*fw_node);
  PlantCanPort plant(*pl_node);
  OperatorCanPort station(*op_node);
  std::uint64_t supervisor_frames = 0;
  Recorder rec(*tap, capture, sent);
  bool ok = true;
  for (long n = 0; n < cycles && ok; ++n) {
    const auto k = static_cast<std::uint64_t>(n);
    clock.now_ns += kCyclePeriodNs;
    firmware.send_sync(k);
    ok &= rec.record("SYNC", {{"Cycle", static_cast<double>(k % (1u << 20))}});
    if (k % kHeartbeatPeriodCycles == 0) {
      firmware.send_heartbeat(static_cast<std::uint8_t>(k / 100 % 16));
      ok &= rec.record("FW_HEARTBEAT", {{"FirmwareMode", static_cast<double>(k / 100 % 16)}});
    }
    if (k % 97 == 13) {
      firmware.send_fault(k % 2 == 1, static_cast<std::uint16_t>(k * 31));
      ok &= rec.record("FW_EMERGENCY", {{"EmergencyStop", k % 2 == 1 ? 1.0 : 0.0}, {"FaultCode", static_cast<double>((k * 31) & 0xFFFF)}});
    }
    if (k % 113 == 29) {
      const auto command = static_cast<SupervisorCommand>(k / 113 % 4);
      station.send(command);
      ++supervisor_frames;
      ok &= rec.record("SUPERVISOR", {{"Command", static_cast<double>(command)}});
    }
    std::uint64_t cycle = 0;
    while (plant.poll_sync(cycle)) {
      const SensorState s = sensors_at(cycle);
      plant.write(s);
      ok &= rec.record("SENS_MACHINE", sensor_signals(s));
      if (cycle % kHeartbeatPeriodCycles == 50) {
        plant.send_heartbeat(s.plant_state);
        ok &= rec.record("PLANT_HEARTBEAT", {{"PlantState", static_cast<double>(s.plant_state)}});
      }
      if (cycle % 89 == 7) {
        plant.send_fault(true, static_cast<std::uint16_t>(cycle));
        ok &= rec.record("PLANT_EMERGENCY", {{"EmergencyStop", 1.0}, {"FaultCode", static_cast<double>(cycle & 0xFFFF)}});
      }
    }
    SensorState seen;
    firmware.read(seen);
    const char* message = nullptr;
    Signals signals;
    firmware.write(command_at(k, message, signals));
    ok &= rec.record(message, signals);
  }
  if (!ok) return 1;
  if (firmware.tx_stats().saturated + plant.tx_stats().saturated != 0) {
    std::fputs("vcan-port-capture: a value was outside its signal's range (saturated)\n", stderr);
    return 1;
  }
  std::printf("vcan-port-capture: %ld cycles, %llu frames written to %s\n", cycles,
              static_cast<unsigned long long>(firmware.tx_stats().frames_sent + plant.tx_stats().frames_sent + supervisor_frames),
              argv[2]);
  return 0;
}
