// Sensors: latency in whole cycles, quantisation, seeded noise.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "plant_scenes.hpp"

using namespace exc;
using namespace exc::plant;

TEST_CASE("plant/sensors report with the configured latency in cycles") {
  SensorParameters p;
  p.latency_cycles = 3;
  SensorModel s(p);
  for (int c = 0; c < 20; ++c) {
    s.sample(c, Vec4::Constant(c), Vec4::Constant(-c), Vec4::Zero(), Vec4::Zero());
    const int expected = std::max(0, c - 3);
    CHECK(s.latest().cycle == expected);
    CHECK(s.latest().position[2] == expected);
  }
}

TEST_CASE("plant/sensors quantise positions") {
  SensorParameters p;
  p.position_quantum = Vec4(0.0004, 0.001, 0.001, 0.001);
  SensorModel s(p);
  s.sample(0, Vec4(0.12345, 2.34567, 2.0004, 1.9996), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
  CHECK(s.latest().position[0] == doctest::Approx(0.1236));
  CHECK(s.latest().position[1] == doctest::Approx(2.346));
  CHECK(s.latest().position[2] == doctest::Approx(2.000));
  CHECK(s.latest().position[3] == doctest::Approx(2.000));
}

TEST_CASE("plant/sensors: a quantum too fine to count a value in (a denormal the schema admits) reports the value, not infinity") {
  // Found by the settings mutations: position_quantum 1e-320 is in [0, 0.1], and v / 1e-320
  // overflowed to inf, so quantum * round(inf) reported an infinite position.
  SensorParameters p;
  p.position_quantum = Vec4(1e-320, 1e-320, 1e-300, 0.001);
  SensorModel s(p);
  s.sample(0, Vec4(0.5, 2.34567, 2.0004, 1.9996), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
  CHECK(s.latest().position[0] == 0.5);
  CHECK(s.latest().position[1] == 2.34567);
  CHECK(std::isfinite(s.latest().position[2]));
  CHECK(s.latest().position[2] == doctest::Approx(2.0004).epsilon(1e-12));
  CHECK(s.latest().position[3] == doctest::Approx(2.000));  // the control: a real quantum still rounds
}

TEST_CASE("plant/sensor noise is seeded, reproducible and of the configured size") {
  SensorParameters p;
  p.velocity_noise = Vec4(0.01, 0.002, 0.002, 0.002);
  p.seed = 42;
  SensorModel a(p), b(p);
  p.seed = 43;
  SensorModel c(p);
  double sum2 = 0;
  bool differs = false;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    a.sample(k, Vec4::Zero(), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
    b.sample(k, Vec4::Zero(), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
    c.sample(k, Vec4::Zero(), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
    REQUIRE(a.latest().velocity == b.latest().velocity);
    differs = differs || a.latest().velocity != c.latest().velocity;
    sum2 += a.latest().velocity[0] * a.latest().velocity[0];
  }
  CHECK(differs);
  CHECK(std::sqrt(sum2 / n) == doctest::Approx(0.01).epsilon(0.03));
}

TEST_CASE("plant/sensors: pressure noise is seeded and of the configured size on every chamber and pump, before the quantum, and off draws nothing") {
  SensorParameters p;
  p.pressure_noise = 20e3;
  p.pressure_quantum = 1e3;
  p.seed = 7;
  SensorModel a(p), b(p);
  const Vec4 pa(3e6, 5e6, 7e6, 9e6), pb(4e6, 6e6, 8e6, 10e6);
  const Vec2 pump(12e6, 13e6);
  // Per reading: the sum of squares of its deviation from the truth, and of the quantum's remainder.
  double sum2[10] = {}, off_grid = 0;
  const int n = 20000;
  for (int k = 0; k < n; ++k) {
    a.sample(k, Vec4::Zero(), Vec4::Zero(), pa, pb, pump);
    b.sample(k, Vec4::Zero(), Vec4::Zero(), pa, pb, pump);
    const SensorReading& r = a.latest();
    REQUIRE(r.pressure_a == b.latest().pressure_a);
    REQUIRE(r.pump_pressure == b.latest().pump_pressure);
    const double got[10] = {r.swing_pressure.x(), r.swing_pressure.y(), r.pressure_a[0], r.pressure_b[0], r.pressure_a[1],
                            r.pressure_b[1], r.pressure_a[2], r.pressure_b[2], r.pump_pressure[0], r.pump_pressure[1]};
    const double truth[10] = {pa[0], pb[0], pa[1], pb[1], pa[2], pb[2], pa[3], pb[3], pump[0], pump[1]};
    for (int c = 0; c < 10; ++c) {
      sum2[c] += (got[c] - truth[c]) * (got[c] - truth[c]);
      off_grid = std::max(off_grid, std::abs(got[c] / 1e3 - std::round(got[c] / 1e3)));
    }
  }
  // The 1 kPa quantum adds q^2 / 12 to the variance: sqrt(20^2 + 1/12) kPa, within sampling error (~1 %).
  for (int c = 0; c < 10; ++c) {
    CAPTURE(c);
    CHECK(std::sqrt(sum2[c] / n) == doctest::Approx(std::sqrt(20e3 * 20e3 + 1e6 / 12)).epsilon(0.03));
  }
  CHECK(off_grid < 1e-6);  // every reading on the quantum's grid: noise first, then the converter
  // Off (the default): the readings are the truth, and no pressure draw moves the velocity noise of a
  // model with the same seed (with it on, the draws interleave: the velocity noise differs).
  SensorParameters off;
  off.velocity_noise = Vec4(0.01, 0.002, 0.002, 0.002);
  SensorParameters on = off;
  on.pressure_noise = 1e3;
  SensorModel c(off), e(on);
  SensorModel no_pressures(off);
  bool shifted = false;
  for (int k = 0; k < 100; ++k) {
    c.sample(k, Vec4::Zero(), Vec4::Zero(), pa, pb, pump);
    no_pressures.sample(k, Vec4::Zero(), Vec4::Zero(), Vec4::Zero(), Vec4::Zero());
    e.sample(k, Vec4::Zero(), Vec4::Zero(), pa, pb, pump);
    REQUIRE(c.latest().pressure_a == pa.tail<3>());
    REQUIRE(c.latest().pump_pressure == pump);
    REQUIRE(c.latest().velocity == no_pressures.latest().velocity);
    shifted = shifted || e.latest().velocity != c.latest().velocity;
  }
  CHECK(shifted);
}
