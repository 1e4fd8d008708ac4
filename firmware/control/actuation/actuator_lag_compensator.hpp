#pragma once
// Inversion of a known first-order actuator lag (machine.md "Hydraulics", the plant's `limited`
// fidelity): the control laws ask for an effort r, the actuator delivers y' = (u - y) / T_a. The
// compensator keeps a model y_hat of the delivered effort and commands
//     u = y_hat + (T_a / T_c) (r - y_hat),
// so that the delivered effort follows r with the shorter time constant T_c instead of T_a. The
// high-frequency gain T_a / T_c bounds how much measurement noise the lead amplifies; full inversion
// (T_c -> 0) would multiply it by T_a / period. u is clamped to the effort limits and y_hat is
// advanced with the clamped u, so a saturated actuator is modelled as such (no wind-up).
// T_a = 0 (the paper's ideal force actuators) passes r through unchanged. Allocation-free.
#include <cmath>
#include <cstdint>

#include "control/laws/effort_limits.hpp"
#include "model/types.hpp"

namespace exc::control {

class ActuatorLagCompensator {
 public:
  ActuatorLagCompensator() = default;
  // lag T_a (s, 0: none), target T_c (s, 0 < T_c <= T_a), period of the calls (s).
  ActuatorLagCompensator(double lag, double target, double period, const EffortLimits& limits)
      : lead_(lag > 0 ? lag / target : 1.0),
        alpha_(lag > 0 ? 1.0 - std::exp(-period / lag) : 1.0),
        active_(lag > 0),
        limits_(limits) {}

  bool active() const { return active_; }

  // The actuator is taken to deliver 'effort' now (e.g. it was holding the last command).
  void reset(const Vec4& effort) { limits_.saturate(effort, y_hat_); }

  // The command that makes the delivered effort approach r with time constant T_c.
  Vec4 apply(const Vec4& r) {
    if (!active_) return r;
    Vec4 u;
    clamped_ = limits_.saturate(y_hat_ + lead_ * (r - y_hat_), u);
    y_hat_ += alpha_ * (u - y_hat_);  // the actuator's own lag, exact over one period
    return u;
  }

  // The model's estimate of the effort the actuator delivers.
  const Vec4& delivered() const { return y_hat_; }
  // Bit j set: the last apply() clamped joint j's command to its limit.
  std::uint8_t clamped() const { return clamped_; }

 private:
  double lead_ = 1.0, alpha_ = 1.0;
  bool active_ = false;
  std::uint8_t clamped_ = 0;
  EffortLimits limits_;
  Vec4 y_hat_ = Vec4::Zero();
};

}  // namespace exc::control
