#pragma once
// Commanded against delivered flow, per function (docs/safety.md, H1): a spool stuck open or
// running away passes oil the valve stage did not ask for. The firmware sees the oil it asked for
// (the valve stage's commanded flow per piston area u, through a first-order lag of the spool) and
// the oil that arrived: the motion plus the oil column's compression, dq + d(F / K_h), with F the
// effort measured from the chamber pressures and K_h the oil columns' stiffness at the stroke (the
// chamber continuity dF/dt = K_h (u - v), the force loop's own model). Counting compression is what
// finds a stuck swing spool in tens of milliseconds: the swing's inertia barely moves at first, but
// the oil the spool passes shows at once as pressure. And a load that drives a function against
// centred valves (a rock, a hand on the bucket) compresses the oil as much as it moves it, so it is
// no runaway. Both are high-passed over `window` (a steady map error decays out); the asked
// displacement is summed apart for each direction (c+ and c-, so a reversed command leaves what
// it asked before as an allowance), and a function is implausible when what arrived exceeds, or
// opposes, what was asked:
//   |a| - A + max(0, min(|a|, c_against) - A) > velocity_floor_i * window,  A = (1 + fraction) c_along,
// a the high-passed delivered displacement, c_along the asked one in a's direction, c_against the
// one asked the other way: oil that arrived against what was asked counts up to twice, less the
// allowance of what was asked its way (a law fighting a runaway asks ever harder the other way;
// what did not arrive is no fault by itself). One-sided: a function given less
// than asked (a dead zone, the pumps short, a relief, an end stop) is the tracking error's business,
// not a runaway. While a chamber is at a relief its oil leaves by the relief: that function's sums
// hold. Debounced (`debounce` in a row). While inactive (safe state, effort interface) nothing is
// counted and the sums restart. Fixed-size state, no allocation.
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "model/types.hpp"

namespace exc::safety {

struct PlausibilitySettings {
  bool enabled = true;  // the tracking fault (the sums run regardless: the standstill monitor uses them)
  // rad/s (swing), m/s: how much more flow per piston area than commanded may arrive, averaged over
  // `window`. Default: a share of the nominal machine's top speed of each function (controller_defaults).
  Vec4 velocity_floor = Vec4::Constant(0.03);
  double velocity_fraction = 0.5;  // of the commanded displacement: the command's own allowance (map errors)
  double window = 0.1;             // s, the high-pass time constant of both displacements
  double lag = 0.02;               // s, the response the commands are filtered with (spool, sensing)
  double debounce = 0.01;          // s the test must fail in a row
  // The frozen reading test (frozen_position.hpp): sensor sets in a row, and the asked speed per
  // function above which a motion must show (default: kFrozenSpeedShare of its top speed).
  int frozen_sets = 200;
  Vec4 frozen_speed = Vec4::Constant(0.01);
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, PlausibilitySettings& s) {
  v("enabled", s.enabled);
  v("velocity_floor", s.velocity_floor);
  v("velocity_fraction", s.velocity_fraction);
  v("window", s.window);
  v("lag", s.lag);
  v("debounce", s.debounce);
  v("frozen_sets", s.frozen_sets);
  v("frozen_speed", s.frozen_speed);
}

class VelocityPlausibility {
 public:
  VelocityPlausibility() = default;
  VelocityPlausibility(const PlausibilitySettings& s, double period)
      : s_(s), period_(period), gain_(1.0 - std::exp(-period / (s.lag > 0 ? s.lag : period))),
        decay_(std::exp(-period / (s.window > 0 ? s.window : period))),
        debounce_cycles_(std::max(1, static_cast<int>(std::ceil(s.debounce / period - 1e-9)))) {}

  // One cycle: the commanded flow per area u, the measured position q, the compression F / K_h, and
  // the functions whose chambers are at a relief (bit i). Returns the functions found implausible
  // this cycle (bit i), once per episode.
  std::uint8_t update(bool active, const Vec4& commanded = Vec4::Zero(), const Vec4& position = Vec4::Zero(),
                      const Vec4& compression = Vec4::Zero(), std::uint8_t at_relief = 0) {
    if (!active) {
      expected_.setZero();
      delivered_.setZero();
      asked_pos_.setZero();
      asked_neg_.setZero();
      primed_ = false;  // the next active cycle starts the sums from its own measurement
      run_.setZero();
      return 0;
    }
    if (!primed_) {
      last_position_ = position;
      last_compression_ = compression;
      primed_ = true;
    }
    expected_ += gain_ * (commanded - expected_);
    std::uint8_t found = 0;
    for (int i = 0; i < 4; ++i) {
      const bool hold = ((at_relief >> i) & 1) != 0;
      const double arrived = hold ? 0.0 : (position[i] - last_position_[i]) + (compression[i] - last_compression_[i]);
      delivered_[i] = decay_ * delivered_[i] + arrived;
      const double ask = hold ? 0.0 : expected_[i] * period_;
      asked_pos_[i] = decay_ * asked_pos_[i] + std::max(ask, 0.0);
      asked_neg_[i] = decay_ * asked_neg_[i] - std::min(ask, 0.0);
      const double a = delivered_[i];
      const double along = a >= 0 ? asked_pos_[i] : asked_neg_[i];
      const double against = a >= 0 ? asked_neg_[i] : asked_pos_[i];
      const double allowed = (1 + s_.velocity_fraction) * along;
      excess_[i] = std::abs(a) - allowed + std::max(0.0, std::min(std::abs(a), against) - allowed);
      const double ratio = excess_[i] / (s_.velocity_floor[i] * s_.window);
      worst_ratio_[i] = std::max(worst_ratio_[i], ratio);
      if (ratio > 1) {
        if (++run_[i] == debounce_cycles_) found |= static_cast<std::uint8_t>(1u << i);
      } else {
        run_[i] = 0;
      }
    }
    last_position_ = position;
    last_compression_ = compression;
    return found;
  }
  // The functions beyond their floor for the debounce time now (bit i), found this cycle or before.
  std::uint8_t implausible() const {
    std::uint8_t bits = 0;
    for (int i = 0; i < 4; ++i)
      if (run_[i] >= debounce_cycles_) bits |= static_cast<std::uint8_t>(1u << i);
    return bits;
  }
  const Vec4& expected() const { return expected_; }     // the lagged commanded flow per area
  const Vec4& delivered() const { return delivered_; }   // high-passed displacement that arrived
  Vec4 asked() const { return asked_pos_ - asked_neg_; }  // high-passed displacement asked for, net
  const Vec4& asked_positive() const { return asked_pos_; }  // ... each way (both >= 0)
  const Vec4& asked_negative() const { return asked_neg_; }
  const Vec4& excess() const { return excess_; }
  // The largest test value over its floor seen per function (1: the edge), for margins in reports.
  const Vec4& worst_ratio() const { return worst_ratio_; }
  int debounce_cycles() const { return debounce_cycles_; }
  const PlausibilitySettings& settings() const { return s_; }

 private:
  PlausibilitySettings s_;
  double period_ = 1e-3, gain_ = 1, decay_ = 0;
  int debounce_cycles_ = 1;
  bool primed_ = false;
  Vec4 expected_ = Vec4::Zero(), delivered_ = Vec4::Zero(), excess_ = Vec4::Zero();
  Vec4 asked_pos_ = Vec4::Zero(), asked_neg_ = Vec4::Zero();  // asked each way (both >= 0)
  Vec4 last_position_ = Vec4::Zero(), last_compression_ = Vec4::Zero(), worst_ratio_ = Vec4::Zero();
  Eigen::Vector4i run_ = Eigen::Vector4i::Zero();
};

}  // namespace exc::safety
