#pragma once
// Commanded against measured motion, per function (docs/safety.md, H1): a spool stuck open or
// running away makes a function move more than, or against, what its valve is told, and push against
// what the law asks. Two tests, each debounced (`debounce` in a row), on the valve interface:
//   velocity  the valve stage's commanded flow per piston area u, through a first-order lag of the
//             spool's and the oil column's response (`lag`), against the estimator's velocity v: the
//             function moves faster than commanded, or against the command,
//               |v| - max(0, sign(v) u_lagged) (1 + fraction) > velocity_floor_i.
//             One-sided: a function slower than commanded (breakaway, a force still building, a
//             load) is the tracking error's business, not a runaway.
//   effort    the law's effort F_d (same lag) against the effort measured from the chamber
//             pressures F: both beyond effort_floor_i and of opposite signs, the cylinder pushes
//             the other way than asked (a spool stuck the other way, before the mass has moved:
//             the swing's inertia lets it move only slowly at first). Not for a flow law (no F_d).
// While inactive (not commanding: safe state, effort interface) nothing is counted and the lags
// restart at the measured values. Fixed-size state, no allocation.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "model/types.hpp"

namespace exc::control {

struct PlausibilitySettings {
  bool enabled = true;
  // rad/s (swing), m/s: how much faster than commanded a function may move. Default: a quarter of
  // the nominal machine's top speed of each function (controller_defaults).
  Vec4 velocity_floor = Vec4::Constant(0.03);
  double velocity_fraction = 0.5;  // of |u_lagged|: the commanded speed's own allowance
  // N m (swing), N: the effort both F_d and F must exceed, of opposite signs. Default: a third of
  // each function's largest effort (controller_defaults).
  Vec4 effort_floor = Vec4::Constant(1e5);
  double lag = 0.05;               // s, the response the commands are filtered with
  double debounce = 0.03;          // s the test must fail in a row
};

class VelocityPlausibility {
 public:
  VelocityPlausibility() = default;
  VelocityPlausibility(const PlausibilitySettings& s, double period)
      : s_(s), gain_(1.0 - std::exp(-period / (s.lag > 0 ? s.lag : period))),
        debounce_cycles_(std::max(1, static_cast<int>(std::ceil(s.debounce / period - 1e-9)))) {}

  // One cycle: the commanded velocity u and the measured v; with has_effort, the law's effort F_d
  // and the measured F. Returns the functions found implausible this cycle (bit i), once per episode.
  std::uint8_t update(bool active, const Vec4& commanded, const Vec4& measured, bool has_effort = false,
                      const Vec4& effort_desired = Vec4::Zero(), const Vec4& effort_measured = Vec4::Zero()) {
    if (!active || !s_.enabled) {
      expected_ = measured;
      effort_expected_ = effort_measured;
      run_.setZero();
      return 0;
    }
    expected_ += gain_ * (commanded - expected_);
    if (has_effort) effort_expected_ += gain_ * (effort_desired - effort_expected_);
    std::uint8_t found = 0;
    for (int i = 0; i < 4; ++i) {
      const double v = measured[i];
      const double along = v >= 0 ? expected_[i] : -expected_[i];  // the command's part in v's direction
      excess_[i] = std::abs(v) - std::max(0.0, along) * (1 + s_.velocity_fraction);
      double ratio = excess_[i] / s_.velocity_floor[i];
      if (has_effort) {
        const double fd = effort_expected_[i], f = effort_measured[i];
        const double opposed = fd * f < 0 ? std::min(std::abs(fd), std::abs(f)) : 0.0;
        ratio = std::max(ratio, opposed / s_.effort_floor[i]);
      }
      worst_ratio_[i] = std::max(worst_ratio_[i], ratio);
      if (ratio > 1) {
        if (++run_[i] == debounce_cycles_) found |= static_cast<std::uint8_t>(1u << i);
      } else {
        run_[i] = 0;
      }
    }
    return found;
  }
  const Vec4& expected() const { return expected_; }
  const Vec4& excess() const { return excess_; }
  const Vec4& effort_expected() const { return effort_expected_; }
  // The largest test value over its floor seen per function (1: the edge), for margins in reports.
  const Vec4& worst_ratio() const { return worst_ratio_; }
  int debounce_cycles() const { return debounce_cycles_; }
  const PlausibilitySettings& settings() const { return s_; }

 private:
  PlausibilitySettings s_;
  double gain_ = 1;
  int debounce_cycles_ = 1;
  Vec4 expected_ = Vec4::Zero(), excess_ = Vec4::Zero(), effort_expected_ = Vec4::Zero(), worst_ratio_ = Vec4::Zero();
  Eigen::Vector4i run_ = Eigen::Vector4i::Zero();
};

}  // namespace exc::control
