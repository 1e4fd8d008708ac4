// The loop clock: monotonic time and the absolute-deadline sleeper's overrun handling.
#include <doctest/doctest.h>

#include <ctime>

#include "hal/clock.hpp"

using namespace exc::hal;

namespace {
void busy_for_ns(std::int64_t ns) {
  const std::int64_t end = monotonic_now_ns() + ns;
  while (monotonic_now_ns() < end) {
  }
}
}  // namespace

TEST_CASE("hal/clock is monotonic") {
  std::int64_t last = monotonic_now_ns();
  for (int i = 0; i < 100000; ++i) {
    const std::int64_t now = monotonic_now_ns();
    CHECK(now >= last);
    last = now;
  }
}

TEST_CASE("hal/deadline sleeper keeps the period on time and counts overruns without catching up") {
  constexpr std::int64_t period = 2'000'000;  // 2 ms: generous for a loaded 2-core machine
  DeadlineSleeper sleeper(period);
  const std::int64_t t0 = monotonic_now_ns();
  sleeper.start(t0);
  for (int i = 0; i < 50; ++i) sleeper.wait_next();
  const std::int64_t elapsed = monotonic_now_ns() - t0;
  // 50 periods: never early (absolute deadlines), and within a generous margin late.
  CHECK(elapsed >= 50 * period);
  CHECK(elapsed < 50 * period + 200'000'000);
  const std::uint64_t overruns_before = sleeper.overruns();

  // Work that takes 3.5 periods: one overrun, at least 3 deadlines skipped, and the wait still sleeps
  // to a deadline that lies after the call (no burst of immediate returns to catch up).
  busy_for_ns(3 * period + period / 2);
  const std::int64_t called = monotonic_now_ns();
  const std::int64_t skipped = sleeper.wait_next();
  const std::int64_t woke = monotonic_now_ns();
  const std::int64_t slept_to = sleeper.next_deadline_ns() - period;
  CHECK(skipped >= 3);
  CHECK(sleeper.overruns() == overruns_before + 1);
  CHECK(sleeper.skipped_periods() >= 3);
  CHECK(slept_to > called);
  CHECK(woke >= slept_to);
  // The grid is kept: deadlines stay on start + k * period.
  CHECK((sleeper.next_deadline_ns() - (t0 + period)) % period == 0);
}
