#include <doctest/doctest.h>

#include "control/laws/effort_limits.hpp"
#include "control/laws/pid.hpp"

using namespace exc;
using namespace exc::control;

TEST_CASE("firmware/effort limits clamp each joint and flag it, non-finite becomes zero") {
  EffortLimits lim;
  lim.min = Vec4(-65000, -387000, -248000, -184000);
  lim.max = Vec4(65000, 776000, 491000, 356000);
  Vec4 out;
  std::uint8_t m = lim.saturate(Vec4(70000, -400000, 1000, std::nan("")), out);
  CHECK(out == Vec4(65000, -387000, 1000, 0));
  CHECK(is_saturated(m, 0));
  CHECK(is_saturated(m, 1));
  CHECK(!is_saturated(m, 2));
  CHECK(is_saturated(m, 3));
  m = lim.saturate(Vec4(1, 2, 3, 4), out);
  CHECK(m == 0);
}

TEST_CASE("firmware/pid anti-windup: the integral freezes while saturated and is clamped") {
  PidGains g;
  g.kp = Vec4::Constant(10);
  g.kv = Vec4::Constant(2);
  g.ki = Vec4::Constant(5);
  g.integral_limit = Vec4::Constant(0.3);
  Pid pid(g);
  const Vec4 e = Vec4::Constant(0.1);
  // Joint 0 saturated, the others not, for 1 s.
  for (int k = 0; k < 1000; ++k) pid.update(e, Vec4::Zero(), 1e-3, 0b0001);
  CHECK(pid.integral()[0] == 0);
  CHECK(pid.integral()[1] == doctest::Approx(0.1));
  // Long enough to hit the clamp.
  for (int k = 0; k < 10000; ++k) pid.update(e, Vec4::Zero(), 1e-3, 0);
  CHECK(pid.integral()[1] == doctest::Approx(0.3));
  const Vec4 u = pid.update(Vec4::Zero(), Vec4::Constant(1), 1e-3, 0);
  CHECK(u[1] == doctest::Approx(2 * 1 + 5 * 0.3));
}

TEST_CASE("firmware/pid without anti-windup would wind up: the frozen integral recovers faster") {
  // Windup scenario: a long saturation, then the error reverses. With conditional integration the
  // integral is zero when the error reverses; a plain integrator would still carry e*T.
  PidGains g;
  g.kp = Vec4::Constant(1);
  g.kv = Vec4::Zero();
  g.ki = Vec4::Constant(1);
  Pid with(g), without(g);
  for (int k = 0; k < 2000; ++k) {
    with.update(Vec4::Constant(0.5), Vec4::Zero(), 1e-3, 0b1111);
    without.update(Vec4::Constant(0.5), Vec4::Zero(), 1e-3, 0);
  }
  CHECK(with.integral().norm() == 0);
  CHECK(without.integral()[0] == doctest::Approx(1.0));
}
