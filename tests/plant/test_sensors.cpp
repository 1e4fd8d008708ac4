// Sensors: latency in whole cycles, quantisation, seeded noise.
#include <doctest/doctest.h>

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
