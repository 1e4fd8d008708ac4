#pragma once
// What the hal tests send through the ports: the plant's report and the firmware's command of cycle
// k as smooth functions of k inside the signal ranges (so every received value can be checked
// against the cycle it claims), their comparison at the codec's resolution, plain frames and a
// simulated clock for the memory bus.
#include <cmath>
#include <cstdint>

#include "hal/can_ports.hpp"

namespace exc::hal::test {

// What the plant reports at cycle k: every value of SENS_MACHINE, pressures only when hydraulic.
inline SensorState sensors_for(std::uint64_t k, bool hydraulic) {
  SensorState s;
  const double t = 1e-3 * static_cast<double>(k);
  s.cycle = k;
  s.position = {1.2 * std::sin(t), 2.2 + 0.5 * std::sin(0.7 * t), 2.8 + 0.6 * std::cos(0.5 * t), 2.0 + 0.3 * std::sin(t)};
  s.velocity = {1.2 * std::cos(t), 0.35 * std::cos(0.7 * t), -0.3 * std::sin(0.5 * t), 0.3 * std::cos(t)};
  if (hydraulic) {
    for (int axis = 0; axis < kAxisCount; ++axis) {
      s.pressure_a[axis] = 20e6 + 10e6 * std::sin(t + axis);
      s.pressure_b[axis] = 15e6 + 5e6 * std::cos(t + axis);
    }
    s.pump_pressure = {25e6 + 9e6 * std::sin(3 * t), 24e6 + 9e6 * std::cos(3 * t)};
  }
  s.pressure_valid = hydraulic;
  s.plant_state = static_cast<std::uint8_t>(k % 7);
  s.plant_faults = static_cast<std::uint8_t>(k % 251);
  return s;
}

// What the firmware commands at cycle k in `mode`.
inline CommandState command_for(std::uint64_t k, CommandMode mode) {
  CommandState c;
  const double t = 1e-3 * static_cast<double>(k);
  c.mode = mode;
  c.cycle = k;
  switch (mode) {
    case CommandMode::effort:
      c.value = {60000 * std::sin(t), 700000 * std::cos(t), -500000 * std::sin(0.3 * t), 300000 * std::cos(2 * t)};
      break;
    case CommandMode::valve:
      c.value = {std::sin(t), std::cos(t), -std::sin(0.3 * t), 0.5 * std::cos(2 * t)};
      break;
    case CommandMode::pilot:
      for (int axis = 0; axis < kAxisCount; ++axis) {
        c.pilot_a[axis] = 2.5e6 + 2.5e6 * std::sin(t + axis);
        c.pilot_b[axis] = 2.5e6 - 2.5e6 * std::sin(t + axis);
      }
      break;
  }
  return c;
}

// Equal within half a step of each signal's resolution (SENS_MACHINE's scaling in the DBC).
inline bool same_sensors(const SensorState& got, const SensorState& want) {
  const double tol_position[] = {0.5e-6, 0.5e-5, 0.5e-5, 0.5e-5};
  constexpr double kTolPressure = 500 * 1.001;
  for (int i = 0; i < kAxisCount; ++i) {
    if (std::fabs(got.position[i] - want.position[i]) > tol_position[i] * 1.001) return false;
    if (std::fabs(got.velocity[i] - want.velocity[i]) > 0.5e-4 * 1.001) return false;
    if (std::fabs(got.pressure_a[i] - want.pressure_a[i]) > kTolPressure) return false;
    if (std::fabs(got.pressure_b[i] - want.pressure_b[i]) > kTolPressure) return false;
  }
  for (int p = 0; p < kPumpCount; ++p) {
    if (std::fabs(got.pump_pressure[p] - want.pump_pressure[p]) > kTolPressure) return false;
  }
  return got.plant_state == want.plant_state && got.plant_faults == want.plant_faults &&
         got.pressure_valid == want.pressure_valid;
}

inline bool same_command(const CommandState& got, const CommandState& want) {
  if (got.mode != want.mode) return false;
  const double tol_effort[] = {2.0, 12.5, 12.5, 12.5};
  for (int i = 0; i < kAxisCount; ++i) {
    switch (want.mode) {
      case CommandMode::effort:
        if (std::fabs(got.value[i] - want.value[i]) > tol_effort[i] * 1.001) return false;
        break;
      case CommandMode::valve:
        if (std::fabs(got.value[i] - want.value[i]) > 0.00025 * 1.001) return false;
        break;
      case CommandMode::pilot:  // 2 kPa per bit
        if (std::fabs(got.pilot_a[i] - want.pilot_a[i]) > 1000 * 1.001) return false;
        if (std::fabs(got.pilot_b[i] - want.pilot_b[i]) > 1000 * 1.001) return false;
        break;
    }
  }
  return true;
}

// A plain frame: classical 8 bytes, or CAN FD with bit-rate switch and `len` bytes.
inline CanFrame frame_with(std::uint32_t id, std::uint8_t first_byte, bool fd = false, std::uint8_t len = 8) {
  CanFrame f;
  f.id = id;
  f.fd = fd;
  f.brs = fd;
  f.len = len;
  f.data[0] = first_byte;
  for (int i = 1; i < len; ++i) f.data[i] = static_cast<std::uint8_t>(0x10 * i + i / 16);
  return f;
}

// Simulated time for a MemoryBusHub: frames are stamped with `now_ns`, advanced by the test.
struct SimClock {
  std::int64_t now_ns = 1'000'000'000;
  static std::int64_t read(void* self) { return static_cast<SimClock*>(self)->now_ns; }
};

}  // namespace exc::hal::test
