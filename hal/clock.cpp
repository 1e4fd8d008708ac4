#include "hal/clock.hpp"

#include <cerrno>
#include <ctime>

namespace exc::hal {

std::int64_t monotonic_now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

DeadlineSleeper::DeadlineSleeper(std::int64_t period_ns) : period_ns_(period_ns > 0 ? period_ns : 1) {}

void DeadlineSleeper::start(std::int64_t start_ns) { deadline_ns_ = start_ns + period_ns_; }

std::int64_t DeadlineSleeper::wait_next() {
  const std::int64_t now = monotonic_now_ns();
  std::int64_t skipped = 0;
  if (now > deadline_ns_) {
    ++overruns_;
    // Drop every deadline already in the past instead of running them back to back.
    skipped = (now - deadline_ns_) / period_ns_ + 1;
    skipped_ += static_cast<std::uint64_t>(skipped);
    deadline_ns_ += skipped * period_ns_;
  }
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(deadline_ns_ / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(deadline_ns_ % 1'000'000'000);
  while (clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr) == EINTR) {
  }
  deadline_ns_ += period_ns_;
  return skipped;
}

}  // namespace exc::hal
