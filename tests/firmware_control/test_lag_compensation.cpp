// The actuator-lag compensator against an independent actuator: y' = (u - y) / T_a integrated with
// fine RK4 substeps under the zero-order-held command (the compensator's own model uses the exact
// exponential; the two must agree, and the delivered effort must show the target time constant).
#include <doctest/doctest.h>

#include <cmath>

#include "control/actuation/actuator_lag_compensator.hpp"

using namespace exc;
using namespace exc::control;

namespace {

constexpr double kPeriod = 1e-3, kLag = 0.02, kTarget = 0.005;

// One period of the first-order actuator under a held command u, 50 RK4 substeps.
Vec4 actuator_step(const Vec4& y0, const Vec4& u) {
  constexpr int n = 50;
  const double h = kPeriod / n;
  Vec4 y = y0;
  auto f = [&](const Vec4& x) -> Vec4 { return (u - x) / kLag; };
  for (int i = 0; i < n; ++i) {
    const Vec4 k1 = f(y), k2 = f(y + 0.5 * h * k1), k3 = f(y + 0.5 * h * k2), k4 = f(y + h * k3);
    y += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  return y;
}

EffortLimits limits(double bound) {
  EffortLimits l;
  l.min = Vec4::Constant(-bound);
  l.max = Vec4::Constant(bound);
  return l;
}

// Time (s) at which the delivered effort of joint 0 first reaches 63.2 % of a step to 'r'.
double rise_time(bool compensate) {
  ActuatorLagCompensator c(compensate ? kLag : 0.0, kTarget, kPeriod, limits(1e7));
  c.reset(Vec4::Zero());
  const Vec4 r = Vec4::Constant(1e5);
  Vec4 y = Vec4::Zero();
  for (int k = 1; k <= 200; ++k) {
    y = actuator_step(y, c.apply(r));
    if (y[0] >= (1 - std::exp(-1.0)) * r[0]) return k * kPeriod;
  }
  return INFINITY;
}

}  // namespace

TEST_CASE("firmware/actuator-lag compensation: a 20 ms actuator answers a step with the 5 ms target time constant") {
  const double compensated = rise_time(true), plain = rise_time(false);
  MESSAGE("63 % rise: compensated " << compensated * 1e3 << " ms, uncompensated " << plain * 1e3 << " ms");
  // The discrete lead gives tau = -T / ln(1 - (1 - e^(-T/T_a)) T_a / T_c) = 4.6 ms; plain: T_a.
  CHECK(compensated >= 0.004);
  CHECK(compensated <= 0.006);
  CHECK(plain >= 0.019);
  CHECK(plain <= 0.022);  // the first whole period past 20 ms
}

TEST_CASE("firmware/actuator-lag compensation: its actuator model matches the integrated actuator, within limits, with no wind-up") {
  const double bound = 2e5;
  ActuatorLagCompensator c(kLag, kTarget, kPeriod, limits(bound));
  const Vec4 y0(1e4, -2e4, 0, 5e4);
  c.reset(y0);
  Vec4 y = y0;
  double worst_model_error = 0, worst_overshoot = 0;
  bool within = true;
  for (int k = 0; k < 300; ++k) {
    // A step far beyond the limits (the lead saturates), then back to a value inside them.
    const Vec4 r = k < 150 ? Vec4(1.5e5, -1.8e5, 1e6, -1e6) : Vec4(0, 0, 1e5, -1e5);
    const Vec4 u = c.apply(r);
    if (k == 0) CHECK(c.clamped() == 0b1111);  // every joint's lead overshoots the limit at the step
    if (k == 299) CHECK(c.clamped() == 0);
    within = within && (u.array().abs() <= bound).all();
    y = actuator_step(y, u);
    worst_model_error = std::max(worst_model_error, (c.delivered() - y).cwiseAbs().maxCoeff());
    // A first-order approach with lead gain alpha T_a / T_c < 1 per step never passes its target.
    if (k >= 150) worst_overshoot = std::max({worst_overshoot, 1e5 - y[2], -y[0]});
    if (k < 150) worst_overshoot = std::max({worst_overshoot, y[0] - 1.5e5, -1.8e5 - y[1]});
  }
  MESSAGE("model vs integrated actuator: " << worst_model_error << " N; overshoot " << worst_overshoot << " N");
  CHECK(within);
  CHECK(worst_model_error < 1e-6 * bound);
  CHECK(worst_overshoot <= 1e-6 * bound);
  // No wind-up: 150 periods after the step back the delivered effort sits at the new request.
  CHECK(std::abs(y[2] - 1e5) < 1.0);
  CHECK(std::abs(y[0]) < 1.0);
}

TEST_CASE("firmware/actuator-lag compensation: no lag configured passes the request through unchanged") {
  ActuatorLagCompensator c(0.0, kTarget, kPeriod, limits(1e5));
  CHECK_FALSE(c.active());
  const Vec4 r(3e5, -1, 0.5, 7);  // even beyond the limits: the control laws saturate, not this stage
  CHECK(c.apply(r) == r);
}
