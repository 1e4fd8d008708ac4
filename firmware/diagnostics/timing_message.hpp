#pragma once
// One PerfCounter as the timing_t telemetry message (the firmware's stages and the plant's step all
// publish theirs on EXC_TIMING).
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "diagnostics/perf_counter.hpp"
#include "exlcm/timing_t.hpp"

namespace exc::diagnostics {

inline void fill_timing(const PerfCounter& c, std::int8_t stage, std::int64_t utime, exlcm::timing_t& m) {
  m.utime = utime;
  m.stage = stage;
  m.count = static_cast<std::int64_t>(c.count());
  m.min_us = c.min_us();
  m.median_us = c.median_us();
  m.p99_us = c.p99_us();
  m.max_us = c.max_us();
  m.overruns = static_cast<std::int64_t>(c.overruns());
  m.skipped = 0;
  // Re-bin the counter's log histogram onto 64 linear bins covering twice the p99 (the one just
  // read: each percentile is a pass over the histogram, a thousand instructions on the Cortex-M7).
  const double span = std::max(1.0, 2 * m.p99_us);
  m.bin_width_us = span / 64;
  std::fill(std::begin(m.bins), std::end(m.bins), 0);
  const auto& h = c.histogram();
  for (int b = 0; b <= c.top_bucket(); ++b) {
    if (h[b] == 0) continue;
    const double centre = PerfCounter::upper_edge_us(b) / std::sqrt(PerfCounter::kRatio);
    const int bin = std::min(63, static_cast<int>(centre / m.bin_width_us));
    m.bins[bin] += h[b];
  }
}


}  // namespace exc::diagnostics
