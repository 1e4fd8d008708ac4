#pragma once
// Tracking figures of one run, per active axis: RMS and max |q_a - q_d| over the tracked cycles.
// Accumulated in the loop (no allocation), read at the end.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>

#include "model/types.hpp"

namespace exc::app {

class TrackingMetrics {
 public:
  void add(const Vec4& q_actual, const Vec4& q_desired) {
    for (int j = 0; j < kNumActive; ++j) {
      const double e = q_actual[j] - q_desired[j];
      sum_sq_[j] += e * e;
      max_abs_[j] = std::max(max_abs_[j], std::abs(e));
    }
    ++samples_;
  }
  std::int64_t samples() const { return samples_; }
  double rms(int joint) const { return samples_ ? std::sqrt(sum_sq_[joint] / samples_) : 0.0; }
  double max_abs(int joint) const { return max_abs_[joint]; }

 private:
  std::array<double, kNumActive> sum_sq_{};
  std::array<double, kNumActive> max_abs_{};
  std::int64_t samples_ = 0;
};

}  // namespace exc::app
