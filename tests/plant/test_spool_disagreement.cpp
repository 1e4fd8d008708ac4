// The onset of a stuck spool's disagreement (harness/spool_disagreement.hpp), which the stop
// requirement's R1 counts from, on spools written here in closed form against the spool monitor's
// stated limits (firmware/safety/spool_monitor.hpp): further from neutral than the healthy spool by
// more than `excess`, on the other side of neutral by more than `band`, off neutral by more than
// `band` where the healthy one is neutral, each past the measurement's resolution; never for a spool
// stuck nearer neutral than commanded.
#include <doctest/doctest.h>

#include <cmath>

#include "harness/spool_disagreement.hpp"

using namespace exc;

TEST_CASE("plant/spool disagreement: a spool stuck open as its command centres disagrees once the healthy spool has closed by the monitor's excess, at tau ln(s0 / (s0 - excess - resolution))") {
  const safety::SpoolMonitorSettings limits;
  const double r = sim::spool_resolution(1e-3);
  sim::SpoolDisagreement d(limits, r);
  const double s0 = 0.7, tau = 0.03, dt = 1e-3, stick = 2.0;
  for (int k = 0; k < 200; ++k) {
    const double t = stick + k * dt;
    Vec4 spool(0.1, s0, -0.2, 0.0), healthy = spool;
    healthy[1] = s0 * std::exp(-(t - stick) / tau);  // the command centred at the stick
    d.record(t, spool, healthy);
  }
  const double expected = stick + std::ceil(tau * std::log(s0 / (s0 - limits.excess - r)) / dt - 1e-9) * dt;
  CHECK(d.function() == 1);
  CHECK(d.onset() == doctest::Approx(expected).epsilon(1e-12));
}

TEST_CASE("plant/spool disagreement: a runaway past the command, a reversed spool and one off neutral with neutral asked disagree at once, and one stuck nearer neutral than asked or within the band never") {
  const safety::SpoolMonitorSettings limits;
  struct Case {
    double spool, healthy;
    bool disagrees;
  };
  const Case cases[] = {
      {0.3 + limits.excess + 0.01, 0.3, true},    // further out than asked by more than the excess
      {0.3 + limits.excess - 0.01, 0.3, false},   // within it
      {-limits.band - 0.01, 0.3, true},           // the other side of neutral
      {-limits.band + 0.01, 0.3, false},
      {limits.band + 0.01, -0.4, true},           // the other side, retracting asked
      {-0.4 - limits.excess - 0.01, -0.4, true},  // further out, retracting
      {limits.band + 0.01, 0.5 * limits.neutral_expected, true},   // off neutral, neutral asked
      {limits.band - 0.01, 0.5 * limits.neutral_expected, false},
      {0.2, 0.8, false},                          // nearer neutral than asked: the blind side
      {0.0, -0.9, false},
  };
  for (const Case& c : cases) {
    CAPTURE(c.spool);
    CAPTURE(c.healthy);
    sim::SpoolDisagreement d(limits, 0.0);
    CHECK(d.disagrees(c.spool, c.healthy) == c.disagrees);
    d.record(1.0, Vec4(0, 0, c.spool, 0), Vec4(0, 0, c.healthy, 0));
    CHECK(d.onset() == (c.disagrees ? 1.0 : -1.0));
    CHECK(d.function() == (c.disagrees ? 2 : -1));
  }
  // Only the first onset counts.
  sim::SpoolDisagreement d(limits, 0.0);
  d.record(1.0, Vec4(0, 0.9, 0, 0), Vec4(0, 0.3, 0, 0));
  d.record(1.5, Vec4(0.9, 0, 0, 0), Vec4(0.0, 0, 0, 0));
  CHECK(d.onset() == 1.0);
  CHECK(d.function() == 1);
}

TEST_CASE("plant/spool disagreement: a spool stuck within the LVDT's resolution of a limit does not disagree, one past it does") {
  // The resolution: 3 standard deviations of the LVDT (0.1 % of the stroke by default) and the bus's
  // 0.1 % quantum (SENS_MACHINE, docs/safety.md).
  const double r = sim::spool_resolution(1e-3);
  CHECK(r == doctest::Approx(0.004).epsilon(1e-12));
  CHECK(sim::spool_resolution(0.0) == doctest::Approx(0.001).epsilon(1e-12));
  const safety::SpoolMonitorSettings limits;
  const sim::SpoolDisagreement d(limits, r);
  // Neutral asked: a spool 0.6 per mille past the band (inside the noise), and one past band + r.
  CHECK_FALSE(d.disagrees(limits.band + 0.0006, 0.0));
  CHECK(d.disagrees(limits.band + r + 0.0005, 0.0));
  CHECK_FALSE(d.disagrees(0.5 + limits.excess + 0.5 * r, 0.5));
  CHECK(d.disagrees(0.5 + limits.excess + 1.5 * r, 0.5));
}
