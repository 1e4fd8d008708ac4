#pragma once
// Where along the task's path the machine is told to be, cycle by cycle: the task's own clock from
// the start of tracking, paced to the pumps (pump_pacing.hpp, controller.pump_pacing) or slowed to
// rest by a stop along the path (path_stop.hpp). Allocation-free after construction.
#include "control/task/path_stop.hpp"
#include "control/task/pump_pacing.hpp"
#include "control/task/task.hpp"

namespace exc::control {

// The clock's own settings (ControllerConfig's `path_clock` member); it takes the period beside them.
struct PathClockSettings {
  // A stop along the path (an operator's stop, a stop request) slows the path so that each function
  // decelerates at most its top speed per this time (path_stop.hpp): a function at top speed stops
  // in 0.63 s over its path, a slower one sooner. About the ramp an operator's joystick release gives.
  double stop_ramp_time = 0.4;  // s
  // Valve interface: the path's clock slowed while the path asks the pumps for more than
  // pump_pacing_share of their flow (pump_pacing.hpp), the run lengthened by what that costs. Off by
  // default: the path's times are then the task's, and a path the pumps cannot follow lags until the
  // tracking limit stops it.
  bool pump_pacing = false;
  double pump_pacing_share = 0.9;
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, PathClockSettings& s) {
  v("stop_ramp_time", s.stop_ramp_time);
  v("pump_pacing", s.pump_pacing);
  v("pump_pacing_share", s.pump_pacing_share);
}

class PathClock {
 public:
  PathClock(const Task& task, const Machine& nominal, const PathClockSettings& settings, double period);

  // Tracking begins at loop time t, at the path's first point.
  void start(double t) {
    track_start_ = t;
    pacing_.start(task_.start_time());
  }
  // A stop along the path from loop time t: the path's clock falls to rest from the rate it had.
  void begin_stop(double t);
  void cancel_stop() { stop_.cancel(); }
  bool stopping() const { return stop_.active(); }
  // A stop along the path is still slowing the path at loop time t.
  bool stop_moving(double t) const { return stop_.active() && !stop_.done(t - stop_start_); }
  // The path time at loop time t, and its clock's rate and the rate's derivative.
  double time_at(double t, double& rate, double& rate_dot) const;
  double time_at(double t) const {
    double rate = 1, rate_dot = 0;
    return time_at(t, rate, rate_dot);
  }
  // This tracking cycle's desired motion at loop time t (a paced clock steps on to the next cycle);
  // returns the path time.
  double desired(double t, Vec4& q, Vec4& qd, Vec4& qdd);

 private:
  double unslowed_time(double t) const { return t - track_start_ + task_.start_time(); }

  const Task& task_;
  Vec4 speed_max_;
  double stop_ramp_time_;
  bool paced_;
  PumpPacing pacing_;
  PathStop stop_;
  double stop_start_ = 0;   // s, loop time the stop along the path began
  double track_start_ = 0;  // s, loop time tracking began
};

}  // namespace exc::control
