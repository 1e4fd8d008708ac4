#pragma once
// What the hal tests send through the ports: the plant's report and the firmware's command of cycle
// k as smooth functions of k inside the signal ranges (so every received value can be checked
// against the cycle it claims), their comparison at the codec's resolution, and a plain frame.
#include <cmath>
#include <cstdint>

#include "hal/can_ports.hpp"

namespace exc::hal::test {

// What the plant reports at cycle k, and what the firmware commands at cycle k: smooth functions of
// k inside the signal ranges, so every received value can be checked against the cycle it claims.
inline SensorState sensors_for(std::uint64_t k, bool hydraulic) {
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

inline CommandState command_for(std::uint64_t k, CommandMode mode) {
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

inline bool same_motion(const SensorState& got, const SensorState& want) {
  const double tol_position[] = {0.5e-6, 0.5e-5, 0.5e-5, 0.5e-5};
  for (int i = 0; i < kAxisCount; ++i) {
    if (std::fabs(got.position[i] - want.position[i]) > tol_position[i] * 1.001) return false;
    if (std::fabs(got.velocity[i] - want.velocity[i]) > 0.5e-4 * 1.001) return false;
  }
  return got.plant_state == want.plant_state && got.plant_faults == want.plant_faults;
}

inline bool same_command(const CommandState& got, const CommandState& want) {
  const double tol_effort[] = {2.0, 12.5, 12.5, 12.5};
  for (int i = 0; i < kAxisCount; ++i) {
    const double tol = (want.mode == CommandMode::effort ? tol_effort[i] : 0.00025) * 1.001;
    if (std::fabs(got.value[i] - want.value[i]) > tol) return false;
  }
  return got.mode == want.mode;
}

inline CanFrame frame_with(std::uint32_t id, std::uint8_t first_byte) {
  CanFrame f;
  f.id = id;
  f.dlc = 8;
  f.data[0] = first_byte;
  for (int i = 1; i < 8; ++i) f.data[i] = static_cast<std::uint8_t>(0x10 * i);
  return f;
}

}  // namespace exc::hal::test
