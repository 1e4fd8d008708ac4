// Sensors: quantisation, seeded noise, latency (fixed ring).
#include "sim_plant/sensors.hpp"

#include <cmath>

namespace exc::plant {

SensorModel::SensorModel(const SensorParameters& params) : params_(params) { reset(); }

void SensorModel::reset() {
  rng_.seed(params_.seed);
  spool_rng_.seed(params_.seed ^ 0x5A5A5A5A5A5A5A5AULL);
  normal_.reset();
  spool_normal_.reset();
  ring_.fill(SensorReading{});
  write_index_ = read_index_ = filled_ = 0;
}

double SensorModel::quantise(double v, double quantum) {
  if (!(quantum > 0)) return v;
  // A quantum too fine to count the value in (a denormal: v / quantum overflows) resolves it fully.
  const double steps = v / quantum;
  return std::isfinite(steps) ? quantum * std::round(steps) : v;
}

void SensorModel::sample(std::int64_t cycle, const Vec4& q_a, const Vec4& qd_a, const Vec4& p_a,
                         const Vec4& p_b, const Vec2& pump, const Vec4* spool) {
  SensorReading& r = ring_[write_index_];
  for (int i = 0; i < 4; ++i) {
    // Noise first, then the converter's quantisation, as a real encoder chain does.
    const double pn = params_.position_noise[i] > 0 ? params_.position_noise[i] * normal_(rng_) : 0.0;
    const double vn = params_.velocity_noise[i] > 0 ? params_.velocity_noise[i] * normal_(rng_) : 0.0;
    r.position[i] = quantise(q_a[i] + pn, params_.position_quantum[i]);
    r.velocity[i] = qd_a[i] + vn;
  }
  // Pressures likewise: noise (drawn only when set, so a run without it draws what it drew), then the
  // quantum.
  auto pressure = [this](double p) {
    const double n = params_.pressure_noise > 0 ? params_.pressure_noise * normal_(rng_) : 0.0;
    return quantise(p + n, params_.pressure_quantum);
  };
  for (int i = 0; i < 3; ++i) {
    r.pressure_a[i] = pressure(p_a[i + 1]);
    r.pressure_b[i] = pressure(p_b[i + 1]);
  }
  r.swing_pressure.x() = pressure(p_a[0]);
  r.swing_pressure.y() = pressure(p_b[0]);
  for (int i = 0; i < 2; ++i) r.pump_pressure[i] = pressure(pump[i]);
  // The spools' LVDTs (the bus quantises them, 0.1 % of the stroke).
  for (int i = 0; i < 4; ++i) {
    const double n = spool != nullptr && params_.spool_noise > 0 ? params_.spool_noise * spool_normal_(spool_rng_) : 0.0;
    r.spool[i] = spool != nullptr ? (*spool)[i] + n : 0.0;
  }
  r.cycle = cycle;
  const int n = static_cast<int>(ring_.size());
  const int latency = params_.latency_cycles;
  // Until the ring holds 'latency' older samples, the oldest one is what the bus shows.
  read_index_ = filled_ >= latency ? (write_index_ - latency + n) % n : (write_index_ - filled_ + n) % n;
  if (filled_ < latency) ++filled_;
  write_index_ = (write_index_ + 1) % n;
}

}  // namespace exc::plant
