#pragma once
// What the machine's sensors report each cycle: swing angle and cylinder lengths, their rates and the
// chamber pressures, with quantisation, seeded Gaussian noise and a latency of whole cycles (a fixed
// ring: nothing allocates).
#include <array>
#include <cstdint>
#include <random>

#include "model/types.hpp"

namespace exc::plant {

struct SensorParameters {
  Vec4 position_quantum = Vec4::Zero();  // rad, m (0: none)
  Vec4 position_noise = Vec4::Zero();    // standard deviation, rad, m
  Vec4 velocity_noise = Vec4::Zero();    // standard deviation, rad/s, m/s
  double pressure_quantum = 0;           // Pa (0: none)
  // Pa, standard deviation on every chamber and pump pressure reading: a transmitter's noise and the
  // pumps' ripple as 1 kHz samples see them (0: none, the readings are the circuit's own).
  double pressure_noise = 0;
  // Standard deviation of each spool's LVDT reading, a fraction of the stroke (estimate: a valve
  // actuator's position sensor to about 0.1 % of its stroke; the bus carries 0.1 % a bit). Drawn
  // from a stream of its own, so the other readings draw what they drew without it.
  double spool_noise = 1e-3;
  std::uint64_t seed = 1;
  int latency_cycles = 0;                // 0 .. kMaxLatency
  static constexpr int kMaxLatency = 63;
};

struct SensorReading {
  Vec4 position = Vec4::Zero();  // swing rad, cylinder lengths m
  Vec4 velocity = Vec4::Zero();  // rad/s, m/s
  Vec3 pressure_a = Vec3::Zero(), pressure_b = Vec3::Zero();  // cylinders (boom, arm, bucket), Pa
  Vec2 swing_pressure = Vec2::Zero();  // swing motor ports A, B, Pa
  Vec2 pump_pressure = Vec2::Zero();   // the two pumps, Pa
  Vec4 spool = Vec4::Zero();           // main-valve spools, -1..1 of the stroke (hydraulic plant)
  std::int64_t cycle = 0;        // the plant cycle the values were measured in
};

// Every double of a reading, by name, to a state visitor (as visit_state(HydraulicReport); held to the
// struct by `plant/visit_state visits every double of SensorReading once`).
template <typename Visitor>
void visit_state(const SensorReading& r, Visitor& v) {
  v.visit("sensor reading position", r.position);
  v.visit("sensor reading velocity", r.velocity);
  v.visit("sensor reading pressure_a", r.pressure_a);
  v.visit("sensor reading pressure_b", r.pressure_b);
  v.visit("sensor reading swing_pressure", r.swing_pressure);
  v.visit("sensor reading pump_pressure", r.pump_pressure);
  v.visit("sensor reading spool", r.spool);
}

class SensorModel {
 public:
  SensorModel() = default;
  explicit SensorModel(const SensorParameters& params);
  void reset();
  // Measure the true values of cycle 'cycle'; the reading returned by latest() lags by the latency.
  // p_a, p_b: chamber pressures, swing motor ports first; pump: the two pumps' pressures; spool:
  // the main-valve spools (none on a force-commanded plant: no noise is drawn for them then).
  void sample(std::int64_t cycle, const Vec4& q_a, const Vec4& qd_a, const Vec4& p_a, const Vec4& p_b,
              const Vec2& pump = Vec2::Zero(), const Vec4* spool = nullptr);
  const SensorReading& latest() const { return ring_[read_index_]; }

 private:
  static double quantise(double v, double quantum);
  SensorParameters params_;
  std::mt19937_64 rng_;
  std::mt19937_64 spool_rng_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  std::normal_distribution<double> spool_normal_{0.0, 1.0};
  std::array<SensorReading, SensorParameters::kMaxLatency + 1> ring_{};
  int write_index_ = 0, read_index_ = 0, filled_ = 0;
};

}  // namespace exc::plant
