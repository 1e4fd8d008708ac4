#pragma once
// A controlled stop along the path (docs/safety.md, "The two stops"): the path's clock is slowed to
// a halt, so the machine decelerates on its path instead of wherever centred valves would throw it
// (a spool closing in 30 ms stops a function on its relief; a swing brakes on its crossover reliefs).
//
// With s the time since the stop began, the path time is tau = tau0 + sigma(s), its rate falling on
// a half cosine from 1 to 0 over T:
//     sigma'(s) = (1 + cos(pi s / T)) / 2,  sigma(s) = s / 2 + T / (2 pi) sin(pi s / T),
// so the desired acceleration never steps and the machine comes to rest T / 2 of path time further
// on. Then q_d = q(tau), qd_d = q'(tau) sigma', qdd_d = q''(tau) sigma'^2 + q'(tau) sigma''.
// A joint moving at v along the path decelerates at most pi |v| / (2 T) from the rate's change; T is
// the shortest that keeps this within each function's top speed per ramp_time (v_max / ramp_time):
//     T = (pi / 2) ramp_time max_j |v_j| / v_max_j.
// A path at rest stops at once. Allocation-free.
#include <algorithm>
#include <cmath>

#include "model/types.hpp"

namespace exc::control {

class PathStop {
 public:
  // Begins at path time tau0 where the path moves at path_velocity (joint units per second of path
  // time) and its clock at `rate` (below 1 where it was paced, pump_pacing.hpp): the rate falls from
  // there, rate (1 + cos(pi s / T)) / 2, T from the machine's speed rate x path_velocity.
  void begin(double tau0, const Vec4& path_velocity, const Vec4& speed_max, double ramp_time, double rate = 1) {
    double worst = 0;
    for (int j = 0; j < 4; ++j)
      if (speed_max[j] > 0) worst = std::max(worst, rate * std::abs(path_velocity[j]) / speed_max[j]);
    tau0_ = tau0;
    rate0_ = rate;
    duration_ = 0.5 * kPi * ramp_time * worst;
    active_ = true;
  }
  void cancel() { active_ = false; }
  bool active() const { return active_; }
  double duration() const { return duration_; }            // T, s
  // The longest T: the path's fastest function at its top speed (a task faster is refused at load).
  static double longest(double ramp_time) { return 0.5 * kPi * ramp_time; }
  double path_time_at_rest() const { return tau0_ + 0.5 * rate0_ * duration_; }
  bool done(double s) const { return s >= duration_; }

  // Path time s after the stop began, and its rate and the rate's derivative.
  void path_time(double s, double& tau, double& rate, double& rate_dot) const {
    if (s >= duration_) {
      tau = path_time_at_rest();
      rate = rate_dot = 0;
      return;
    }
    const double w = kPi / duration_;
    tau = tau0_ + rate0_ * (0.5 * s + std::sin(w * s) / (2 * w));
    rate = 0.5 * rate0_ * (1 + std::cos(w * s));
    rate_dot = -0.5 * rate0_ * w * std::sin(w * s);
  }

  // The path's point and derivatives (in path time) made the desired motion of the slowed clock.
  static void scale(double rate, double rate_dot, const Vec4& yd, const Vec4& ydd, Vec4& qd, Vec4& qdd) {
    qd = yd * rate;
    qdd = ydd * (rate * rate) + yd * rate_dot;
  }

 private:
  static constexpr double kPi = 3.14159265358979323846;
  double tau0_ = 0, rate0_ = 1, duration_ = 0;
  bool active_ = false;
};

}  // namespace exc::control
