#include "control/task/path_clock.hpp"

namespace exc::control {

PathClock::PathClock(const Task& task, const Machine& nominal, const PathClockSettings& settings, double period)
    : task_(task),
      speed_max_(nominal.speed_max()),
      stop_ramp_time_(settings.stop_ramp_time),
      paced_(settings.pump_pacing),
      pacing_(nominal, settings.pump_pacing_share, period) {}

void PathClock::begin_stop(double t) {
  const double tau0 = paced_ ? pacing_.tau() : unslowed_time(t);
  Vec4 q, yd, ydd;
  task_.trajectory.evaluate(tau0, q, yd, ydd);
  stop_.begin(tau0, yd, speed_max_, stop_ramp_time_, paced_ ? pacing_.rate() : 1.0);
  stop_start_ = t;
}

double PathClock::time_at(double t, double& rate, double& rate_dot) const {
  if (!stop_.active()) {
    // Paced, the clock is a state stepped once a cycle (desired()), read here at this cycle's t.
    rate = paced_ ? pacing_.rate() : 1;
    rate_dot = paced_ ? pacing_.rate_dot() : 0;
    return paced_ ? pacing_.tau() : unslowed_time(t);
  }
  double tau = 0;
  stop_.path_time(t - stop_start_, tau, rate, rate_dot);
  return tau;
}

double PathClock::desired(double t, Vec4& q, Vec4& qd, Vec4& qdd) {
  double rate = 1, rate_dot = 0;
  const double tau = time_at(t, rate, rate_dot);
  task_.trajectory.evaluate(tau, q, qd, qdd);
  if (stop_.active()) {
    const Vec4 yd = qd, ydd = qdd;  // in path time
    PathStop::scale(rate, rate_dot, yd, ydd, qd, qdd);
  } else if (paced_) {
    const Vec4 yd = qd, ydd = qdd;
    pacing_.update(yd);
    PathStop::scale(pacing_.rate(), pacing_.rate_dot(), yd, ydd, qd, qdd);
    pacing_.advance();
  }
  return tau;
}

}  // namespace exc::control
