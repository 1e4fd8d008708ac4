#pragma once
// The standstill monitor's creep test (docs/safety.md): a quantity's mean rate over back-to-back
// windows of a set length; a function creeps when its mean rate exceeds its limit and has not fallen
// by `slowing` against the window before (a function braking slows from window to window, a ringing
// one averages out, a stuck spool's creep does neither), or, from the first window on, exceeds
// `fast` times its limit going one way through the whole window (its net displacement at least 90 %
// of the range it covered), whatever the window before: a function still that fast, never turning,
// a whole window into a stop is not braking (a stuck spool's motion, ringing on its oil spring as it
// goes, can fall by the slowing share from one window to the next and never stop), while a ringing
// one turns within the window however slowly its mean decays. Fixed-size, no allocation.
#include <cmath>
#include <cstdint>
#include <limits>

#include "model/types.hpp"

namespace exc::safety {

class CreepWindow {
 public:
  void restart() { started_ = false; }

  // One sample x at `cycle`; returns the functions found creeping (bit i) when a window closes, 0
  // otherwise. A limit of infinity leaves a function out.
  std::uint8_t update(const Vec4& x, std::uint64_t cycle, double period, double length, const Vec4& limit, double slowing,
                      double fast = std::numeric_limits<double>::infinity()) {
    if (!started_) {
      origin_ = low_ = high_ = x;
      origin_cycle_ = cycle;
      started_ = true;
      windows_ = 0;
    }
    low_ = low_.cwiseMin(x);
    high_ = high_.cwiseMax(x);
    window_ = static_cast<double>(cycle - origin_cycle_) * period;
    if (window_ < length) return 0;
    const Vec4 mean = (x - origin_) / window_;
    std::uint8_t creeping = 0;
    for (int i = 0; i < 4; ++i) {
      const bool not_slowing = windows_ > 0 && std::abs(mean[i]) > (1 - slowing) * std::abs(mean_[i]);
      const bool one_way = std::abs(x[i] - origin_[i]) >= 0.9 * (high_[i] - low_[i]);
      if (std::abs(mean[i]) > limit[i] && (not_slowing || (one_way && std::abs(mean[i]) > fast * limit[i])))
        creeping |= static_cast<std::uint8_t>(1u << i);
    }
    mean_ = mean;
    ++windows_;
    origin_ = low_ = high_ = x;
    origin_cycle_ = cycle;
    return creeping;
  }
  const Vec4& mean() const { return mean_; }  // the last closed window's mean rate
  double window() const { return window_; }   // s, that window's length

 private:
  Vec4 origin_ = Vec4::Zero(), mean_ = Vec4::Zero();
  Vec4 low_ = Vec4::Zero(), high_ = Vec4::Zero();  // the range x covered in the open window
  std::uint64_t origin_cycle_ = 0;
  double window_ = 0;
  int windows_ = 0;
  bool started_ = false;
};

}  // namespace exc::safety
