#pragma once
// A timing counter in the spirit of PX4's perf_counter: count, min, max, mean, overruns against a
// budget, and a fixed logarithmic histogram (5 % wide buckets from 0.1 us to ~1 s) from which the
// median and the 99th percentile are read. Storage is inside the object: recording never allocates.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace exc::diagnostics {

class PerfCounter {
 public:
  static constexpr int kBuckets = 336;           // 0.1 us * 1.05^336 ~ 1.3 s
  static constexpr double kFirstEdgeUs = 0.1;
  static constexpr double kRatio = 1.05;

  explicit PerfCounter(const char* name = "", double budget_us = 1000) : name_(name), budget_us_(budget_us) {}

  void reset() {
    count_ = overruns_ = 0;
    sum_us_ = last_us_ = 0;
    min_us_ = std::numeric_limits<double>::infinity();
    max_us_ = 0;
    histogram_.fill(0);
    top_ = 0;
  }

  void record_us(double us) {
    last_us_ = us;
    ++count_;
    sum_us_ += us;
    min_us_ = std::min(min_us_, us);
    max_us_ = std::max(max_us_, us);
    if (us > budget_us_) ++overruns_;
    const int b = bucket_of(us);
    ++histogram_[b];
    top_ = std::max(top_, b);
  }
  void record_ns(std::int64_t ns) { record_us(static_cast<double>(ns) * 1e-3); }

  const char* name() const { return name_; }
  double budget_us() const { return budget_us_; }
  std::uint64_t count() const { return count_; }
  std::uint64_t overruns() const { return overruns_; }
  double min_us() const { return count_ ? min_us_ : 0; }
  double max_us() const { return max_us_; }
  double last_us() const { return last_us_; }  // the latest sample (0 before any)
  double mean_us() const { return count_ ? sum_us_ / static_cast<double>(count_) : 0; }
  // Upper edge of the bucket holding the given fraction (0..1) of the samples: a conservative
  // (at most 5 % high) percentile, capped by the exact max.
  double percentile_us(double fraction) const {
    if (count_ == 0) return 0;
    // The samples to reach, as a whole count (the same test as seen >= fraction x count for a whole
    // seen): a 32-bit core converts a 64-bit count to double in a library call, once here rather than
    // per bucket.
    const std::uint64_t target = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(fraction * static_cast<double>(count_))));
    std::uint64_t seen = 0;
    for (int b = 0; b <= top_; ++b) {
      seen += histogram_[b];
      if (seen >= target) return std::min(upper_edge_us(b), max_us_);
    }
    return max_us_;
  }
  double median_us() const { return percentile_us(0.5); }
  double p99_us() const { return percentile_us(0.99); }
  const std::array<std::uint32_t, kBuckets>& histogram() const { return histogram_; }
  // Upper edge of a bucket: 0.1 us * 1.05^(bucket + 1), from a table filled once (the telemetry
  // message re-bins every non-empty bucket by its edge each time it is published).
  static double upper_edge_us(int bucket) {
    if (bucket < 0 || bucket >= kBuckets) return kFirstEdgeUs * std::pow(kRatio, bucket + 1);
    return edges()[static_cast<std::size_t>(bucket)];
  }
  // The highest bucket holding a sample (0 before any): the percentiles and a telemetry message's
  // re-binning stop there, not at the last of the 336.
  int top_bucket() const { return top_; }

 private:
  static const std::array<double, kBuckets>& edges() {
    static const std::array<double, kBuckets> e = [] {
      std::array<double, kBuckets> t{};
      for (int b = 0; b < kBuckets; ++b) t[static_cast<std::size_t>(b)] = kFirstEdgeUs * std::pow(kRatio, b + 1);
      return t;
    }();
    return e;
  }
  // The bucket whose edges hold us: the edges at or below it, counted by bisection of the table (a
  // logarithm per sample cost a few hundred instructions on a Cortex-M7 for each of the loop's ten
  // counters; this costs about nine comparisons).
  static int bucket_of(double us) {
    if (!(us > kFirstEdgeUs)) return 0;
    const auto& e = edges();
    const int b = static_cast<int>(std::upper_bound(e.begin(), e.end(), us) - e.begin());
    return std::min(b, kBuckets - 1);
  }

  const char* name_;
  double budget_us_;
  std::uint64_t count_ = 0, overruns_ = 0;
  double last_us_ = 0;
  double sum_us_ = 0;
  double min_us_ = std::numeric_limits<double>::infinity();
  double max_us_ = 0;
  std::array<std::uint32_t, kBuckets> histogram_{};
  int top_ = 0;
};

}  // namespace exc::diagnostics
