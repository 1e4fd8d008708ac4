#pragma once
// Time for the loop: CLOCK_MONOTONIC in nanoseconds and a sleeper on absolute deadlines.
#include <cstdint>

namespace exc::hal {

// CLOCK_MONOTONIC, ns.
std::int64_t monotonic_now_ns();

// Sleeps to absolute deadlines start + k * period (clock_nanosleep, TIMER_ABSTIME), so sleep jitter
// never accumulates. When a deadline has already passed on arrival, the cycle counts as an overrun
// and the missed periods are skipped: the next deadline is the first one still in the future, so a
// late loop never runs a burst of back-to-back cycles to catch up.
class DeadlineSleeper {
 public:
  explicit DeadlineSleeper(std::int64_t period_ns);
  // Starts the grid: the first deadline is start_ns + period.
  void start(std::int64_t start_ns);
  // Sleeps until the next deadline; returns the number of periods skipped (0 when on time).
  std::int64_t wait_next();
  std::int64_t period_ns() const { return period_ns_; }
  std::int64_t next_deadline_ns() const { return deadline_ns_; }
  std::uint64_t overruns() const { return overruns_; }       // cycles that arrived late
  std::uint64_t skipped_periods() const { return skipped_; }  // deadlines dropped in total

 private:
  std::int64_t period_ns_;
  std::int64_t deadline_ns_ = 0;
  std::uint64_t overruns_ = 0;
  std::uint64_t skipped_ = 0;
};

}  // namespace exc::hal
