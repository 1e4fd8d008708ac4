#include "safety/spool_monitor.hpp"

#include <algorithm>
#include <cmath>

namespace exc::safety {

const char* to_string(SpoolTest test) {
  switch (test) {
    case SpoolTest::none: return "none";
    case SpoolTest::further: return "further from neutral than commanded";
    case SpoolTest::against: return "on the other side of neutral from the command";
    case SpoolTest::neutral: return "off neutral with neutral commanded";
  }
  return "?";
}

SpoolMonitor::SpoolMonitor(const SpoolMonitorSettings& settings, double valve_time_constant, double period)
    : s_(settings), gain_(valve_time_constant > 0 ? -std::expm1(-period / valve_time_constant) : 1.0) {}

void SpoolMonitor::reset() {
  for (int& r : run_) r = 0;
}

void SpoolMonitor::command(const Vec4& target) {
  for (int i = 0; i < 4; ++i) target_[i] = std::clamp(target[i], -1.0, 1.0);
}

int SpoolMonitor::check(bool active, const Vec4& measured) {
  // The set answers the command of the cycle before: the spool moved toward it over one period.
  expected_ += gain_ * (target_ - expected_);
  // Arrived within 1e-12 of the stroke is arrived: a lag that only ever halves its distance would
  // reach the subnormals after about 20 s of a steady command.
  for (int i = 0; i < 4; ++i)
    if (std::abs(expected_[i] - target_[i]) < 1e-12) expected_[i] = target_[i];
  if (!active || !s_.enabled) return -1;  // a set that is not there does not break a run
  int found = -1;
  for (int i = 0; i < 4; ++i) {
    const double e = expected_[i], m = measured[i];
    SpoolTest test = SpoolTest::none;
    double ratio;
    if (std::abs(e) < s_.neutral_expected) {
      ratio = std::abs(m) / s_.band;
      if (ratio > 1) test = SpoolTest::neutral;
    } else {
      const double along = e > 0 ? m : -m;  // the measured spool along the expected direction
      const double further = (along - std::abs(e)) / s_.excess;
      const double against = -along / s_.band;
      ratio = std::max(further, against);
      if (further > 1) test = SpoolTest::further;
      else if (against > 1) test = SpoolTest::against;
    }
    if (!std::isfinite(m)) test = SpoolTest::further;  // a reading that means nothing is no healthy spool
    worst_ratio_ = std::max(worst_ratio_, std::isfinite(ratio) ? ratio : 0.0);
    run_[i] = test == SpoolTest::none ? 0 : run_[i] + 1;
    if (run_[i] >= s_.debounce && found < 0) {
      found = i;
      failed_test_ = test;
      failed_function_ = i;
    }
  }
  return found;
}

}  // namespace exc::safety
