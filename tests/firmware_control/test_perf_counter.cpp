#include <doctest/doctest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "diagnostics/perf_counter.hpp"

using namespace exc::diagnostics;

TEST_CASE("firmware/perf counter: median and p99 from the histogram match the sorted samples within 5 %") {
  PerfCounter pc("control_step", 100.0);
  std::mt19937 rng(11);
  std::lognormal_distribution<double> dist(1.5, 0.6);  // ~4.5 us median, long tail
  std::vector<double> xs;
  for (int i = 0; i < 100000; ++i) {
    const double x = dist(rng);
    xs.push_back(x);
    pc.record_us(x);
  }
  std::sort(xs.begin(), xs.end());
  const double median = xs[xs.size() / 2], p99 = xs[static_cast<std::size_t>(0.99 * xs.size())];
  CHECK(pc.count() == 100000);
  CHECK(pc.min_us() == xs.front());
  CHECK(pc.max_us() == xs.back());
  CHECK(pc.median_us() >= median * 0.999);
  CHECK(pc.median_us() <= median * 1.051);
  CHECK(pc.p99_us() >= p99 * 0.999);
  CHECK(pc.p99_us() <= p99 * 1.051);
  const auto over = static_cast<std::uint64_t>(std::count_if(xs.begin(), xs.end(), [](double x) { return x > 100.0; }));
  CHECK(pc.overruns() == over);
  pc.reset();
  CHECK(pc.count() == 0);
  CHECK(pc.p99_us() == 0);
}
