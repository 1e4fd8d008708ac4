#pragma once
// Saturation of the actuator efforts to the machine's limits (swing torque, cylinder push/pull
// forces), with one flag per joint that the integrators and the adaptation read to stop winding up.
#include <cmath>
#include <cstdint>

#include "model/machine.hpp"
#include "model/types.hpp"

namespace exc::control {

struct EffortLimits {
  Vec4 min = Vec4::Constant(-1e300), max = Vec4::Constant(1e300);

  // Clamps tau into [min, max]; returns the bit mask of saturated joints (bit j = joint j).
  // A non-finite entry is replaced by zero effort and flagged (never sent as NaN).
  std::uint8_t saturate(const Vec4& tau, Vec4& out) const {
    std::uint8_t mask = 0;
    for (int j = 0; j < kNumActive; ++j) {
      double v = tau[j];
      if (!std::isfinite(v)) {
        v = 0;
        mask |= static_cast<std::uint8_t>(1u << j);
      } else if (v > max[j]) {
        v = max[j];
        mask |= static_cast<std::uint8_t>(1u << j);
      } else if (v < min[j]) {
        v = min[j];
        mask |= static_cast<std::uint8_t>(1u << j);
      }
      out[j] = v;
    }
    return mask;
  }
};

inline bool is_saturated(std::uint8_t mask, int joint) { return (mask >> joint) & 1u; }

// The machine's effort limits, as the effort laws and the actuator-lag lead saturate to them.
inline EffortLimits effort_limits_of(const Machine& machine) {
  EffortLimits l;
  l.min = machine.effort_min();
  l.max = machine.effort_max();
  return l;
}

}  // namespace exc::control
