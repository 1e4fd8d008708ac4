// The path's clock paced to the pumps (control/task/pump_pacing.hpp) and the stop along the path from a
// paced rate (control/task/path_stop.hpp), against closed forms and an independent quadrature.
#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "control/task/path_stop.hpp"
#include "control/task/pump_pacing.hpp"
#include "model/machine.hpp"
#include "model/machine_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

constexpr double kPeriod = 1e-3;

// The path's oil per second at rate 1, from the machine file's forces and relief (the areas the
// cylinders push and pull with; the swing motor's displacement likewise): sum A |v| per pump.
double path_flow(const Machine& m, const Vec4& v, int pump) {
  const Vec4 max = m.effort_max(), min = m.effort_min();
  double q = 0;
  for (int j = 0; j < 4; ++j) {
    const int p = m.hydraulics.pumps_merged ? 0 : m.hydraulics.pump_of[static_cast<std::size_t>(j)];
    if (p != pump) continue;
    q += (v[j] >= 0 ? max[j] : -min[j]) / m.relief_pressure * std::abs(v[j]);
  }
  return q;
}

}  // namespace

TEST_CASE("firmware/pump pacing: the target rate holds the path's own oil to the share of the pumps' flow, per filled side and per pump") {
  Machine m = reference_machine();
  const double share = 0.9, pumps = m.hydraulics.pump_flow;
  const PumpPacing merged(m, share, kPeriod);
  // Boom up, arm in (annulus), bucket open: beyond the pumps at these speeds.
  const Vec4 v(0.0, 0.3, -0.4, 0.5);
  const double q = path_flow(m, v, 0);
  REQUIRE(q > share * pumps);
  CHECK(merged.target_rate(v) == doctest::Approx(share * pumps / q).epsilon(1e-12));
  CHECK(merged.target_rate(v) * q == doctest::Approx(share * pumps).epsilon(1e-12));
  // The same speeds the other way fill the other sides: another flow, another rate.
  const double q_back = path_flow(m, -v, 0);
  CHECK(q_back != doctest::Approx(q));
  CHECK(merged.target_rate(-v) == doctest::Approx(std::min(1.0, share * pumps / q_back)).epsilon(1e-12));
  // Within the share: the path keeps its times.
  const Vec4 slow = v * (0.5 * share * pumps / q);
  CHECK(merged.target_rate(slow) == 1.0);
  CHECK(merged.target_rate(Vec4::Zero()) == 1.0);
  // Split pumps: each gives half to its own functions; the rate is the tighter pump's.
  m.hydraulics.pumps_merged = false;
  const PumpPacing split(m, share, kPeriod);
  const double q0 = path_flow(m, v, 0), q1 = path_flow(m, v, 1);
  CHECK(q0 + q1 == doctest::Approx(q));
  const double expected = std::min({1.0, 0.5 * share * pumps / q0, 0.5 * share * pumps / q1});
  CHECK(expected < merged.target_rate(v));
  CHECK(split.target_rate(v) == doctest::Approx(expected).epsilon(1e-12));
}

TEST_CASE("firmware/pump pacing: from full rate toward a constant target through its lag, the path time the sum of its rates (discrete closed form)") {
  const Machine m = reference_machine();
  PumpPacing p(m, 0.9, kPeriod);
  const Vec4 v(0.0, 0.3, -0.4, 0.5);  // a path moving steadily: the target stays
  const double target = p.target_rate(v), T = PumpPacing::kTimeConstant, a = 1 - kPeriod / T;
  REQUIRE(target < 0.9);
  p.start(2.0);
  CHECK(p.tau() == 2.0);
  CHECK(p.rate() == 1.0);
  const int n = 300;
  for (int k = 0; k < n; ++k) {
    p.update(v);
    const double rate_k = target + (1 - target) * std::pow(a, k);
    CHECK(p.rate() == doctest::Approx(rate_k).epsilon(1e-12));
    CHECK(p.rate_dot() == doctest::Approx((target - rate_k) / T).epsilon(1e-9));
    p.advance();
  }
  const double tau = 2.0 + kPeriod * (n * target + (1 - target) * (1 - std::pow(a, n)) / (1 - a));
  CHECK(p.tau() == doctest::Approx(tau).epsilon(1e-12));
  CHECK(p.rate() == doctest::Approx(target).epsilon(1e-2));  // 6 time constants on
}

TEST_CASE("firmware/pump pacing: the paced duration is the path's own within the pumps, and beyond them the integral of dtau / r over the path (an independent quadrature)") {
  const Machine m = reference_machine();
  const PumpPacing p(m, 0.9, kPeriod);
  const Vec4 q0(0.0, 2.10, 3.00, 2.30), q1(0.0, 2.50, 2.40, 1.90);
  for (const double seconds : {2.0, 20.0}) {
    CAPTURE(seconds);
    const JointTrajectory path({0.0, seconds}, {q0, q1});
    // Simpson's rule over path time of 1 / r*(y'(tau)): time spent per unit of path time.
    const int n = 20000;
    const double h = seconds / n;
    double integral = 0;
    Vec4 y, yd, ydd;
    for (int i = 0; i <= n; ++i) {
      path.evaluate(i * h, y, yd, ydd);
      const double w = i == 0 || i == n ? 1 : i % 2 == 1 ? 4 : 2;
      integral += w / p.target_rate(yd);
    }
    integral *= h / 3;
    const double paced = paced_duration(p, path, kPeriod);
    CHECK(paced == doctest::Approx(integral).epsilon(2e-3 / seconds));
    if (seconds == 20.0) CHECK(paced == doctest::Approx(seconds).epsilon(kPeriod / seconds));  // slow: within the pumps
    if (seconds == 2.0) CHECK(paced > seconds + 0.3);  // 1.8x the pumps at its peak
  }
}

TEST_CASE("firmware/path stop: from a paced rate the stop starts at that rate, its ramp from the speed it has, and the path time is the rate's integral") {
  const Vec4 speed_max(0.5, 0.32, 0.5, 0.7), v(0.2, 0.3, -0.4, 0.5);
  const double ramp = 0.4;
  for (const double r0 : {1.0, 0.5, 0.2}) {
    CAPTURE(r0);
    PathStop stop;
    stop.begin(3.0, v, speed_max, ramp, r0);
    // T from the fastest function's actual speed (rate x path speed) over its top speed.
    double worst = 0;
    for (int j = 0; j < 4; ++j) worst = std::max(worst, r0 * std::abs(v[j]) / speed_max[j]);
    const double T = 0.5 * M_PI * ramp * worst;
    CHECK(stop.duration() == doctest::Approx(T));
    double tau = 0, rate = 0, rate_dot = 0;
    stop.path_time(0, tau, rate, rate_dot);
    CHECK(tau == 3.0);
    CHECK(rate == doctest::Approx(r0));
    CHECK(rate_dot == doctest::Approx(0).epsilon(1e-12));
    // The rate integrated over the stop (trapezoid) is the path it covers.
    const int n = 4000;
    double covered = 0, previous = r0;
    for (int i = 1; i <= n; ++i) {
      double t_i = 0, r_i = 0, rd_i = 0;
      stop.path_time(T * i / n, t_i, r_i, rd_i);
      covered += 0.5 * (previous + r_i) * T / n;
      previous = r_i;
    }
    CHECK(covered == doctest::Approx(0.5 * r0 * T).epsilon(1e-6));
    CHECK(stop.path_time_at_rest() == doctest::Approx(3.0 + covered).epsilon(1e-6));
    stop.path_time(2 * T, tau, rate, rate_dot);
    CHECK(rate == 0);
    CHECK(tau == doctest::Approx(3.0 + 0.5 * r0 * T));
  }
}
