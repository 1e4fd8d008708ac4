#include "harness/timing_windows.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace exc::sim {

Timing timing_of(const diagnostics::PerfCounter& c) { return Timing{c.median_us(), c.p99_us(), c.max_us(), c.count()}; }

Timing timing_between(const diagnostics::PerfCounter& before, const diagnostics::PerfCounter& after) {
  // From the histograms: the upper edge of the bucket that holds the fraction.
  std::array<std::uint64_t, diagnostics::PerfCounter::kBuckets> h{};
  Timing t;
  int last = -1;
  for (int b = 0; b < diagnostics::PerfCounter::kBuckets; ++b) {
    const auto i = static_cast<std::size_t>(b);
    h[i] = after.histogram()[i] - before.histogram()[i];
    t.count += h[i];
    if (h[i] > 0) last = b;
  }
  if (t.count == 0) return t;
  auto percentile = [&](double fraction) {
    const double target = fraction * static_cast<double>(t.count);
    std::uint64_t seen = 0;
    for (int b = 0; b <= last; ++b) {
      seen += h[static_cast<std::size_t>(b)];
      if (static_cast<double>(seen) >= target && seen > 0) return diagnostics::PerfCounter::upper_edge_us(b);
    }
    return diagnostics::PerfCounter::upper_edge_us(last);
  };
  t.median_us = percentile(0.5);
  t.p99_us = percentile(0.99);
  t.max_us = diagnostics::PerfCounter::upper_edge_us(last);
  return t;
}

TimingWindows::TimingWindows(std::int64_t cycles, double period) : period_(period) {
  const std::int64_t per_second = std::max<std::int64_t>(1, std::llround(1.0 / period));
  first_end_ = std::min(cycles, per_second);
  last_begin_ = std::max<std::int64_t>(0, cycles - per_second);
}

void TimingWindows::before_cycle(std::int64_t k, const diagnostics::PerfCounter* control, const diagnostics::PerfCounter& plant) {
  if (k != last_begin_ || control == nullptr) return;
  control_last_begin_ = *control;
  plant_last_begin_ = plant;
  last_taken_ = true;
}

void TimingWindows::after_cycle(std::int64_t cycles_run, const diagnostics::PerfCounter* control, const diagnostics::PerfCounter& plant) {
  if (cycles_run != first_end_ || control == nullptr) return;
  control_first_end_ = *control;
  plant_first_end_ = plant;
  first_taken_ = true;
}

void TimingWindows::finish(RunRecord& r, std::int64_t cycles_run, const diagnostics::PerfCounter* control,
                           const diagnostics::PerfCounter& plant) const {
  const diagnostics::PerfCounter empty;
  const diagnostics::PerfCounter& control_end = control != nullptr ? *control : empty;
  r.control_step = timing_of(control_end);
  const diagnostics::PerfCounter& control_first = first_taken_ ? control_first_end_ : control_end;
  const diagnostics::PerfCounter& plant_first = first_taken_ ? plant_first_end_ : plant;
  r.first_second = TimingWindow{0, static_cast<double>(std::min(cycles_run, first_end_)) * period_,
                                timing_between(empty, control_first), timing_between(empty, plant_first)};
  if (last_taken_)
    r.last_second = TimingWindow{static_cast<double>(last_begin_) * period_, static_cast<double>(cycles_run) * period_,
                                 timing_between(control_last_begin_, control_end),
                                 timing_between(plant_last_begin_, plant)};
}

}  // namespace exc::sim
