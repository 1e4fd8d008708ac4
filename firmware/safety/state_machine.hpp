#pragma once
// The firmware's operating modes and their transitions:
//   init -> wait_sensors          once the loop runs (start-up done)
//   wait_sensors -> hold          the first valid sensor frame arrived
//   hold -> track                 tracking requested (and sensors fresh)
//   track -> hold                 stop requested, or the trajectory finished
//   hold/track -> safe_stop       watchdog: no valid sensor frame for longer than the timeout, or a
//                                 fault (model, non-finite command); command: zero flow / brake
//   safe_stop -> hold             latched (docs/safety.md): only when an operator acknowledged the
//                                 stop, the frames are fresh and no fault stands; hold where the
//                                 machine is (FirmwareNode does not request tracking again after it)
// Each transition carries a reason. Pure logic on the inputs; no allocation, no clock of its own.
#include <cstdint>

#include "model/types.hpp"

namespace exc::safety {

enum class Mode : std::uint8_t { init = 0, wait_sensors = 1, hold = 2, track = 3, safe_stop = 4 };
const char* to_string(Mode m);

struct StateMachineInputs {
  double t = 0;                          // s, the loop's time
  bool have_valid_frame = false;         // a valid sensor frame has ever been received
  double last_valid_frame_time = -1e300; // s, time of the latest valid sensor frame
  bool track_requested = false;
  bool stop_requested = false;
  bool trajectory_finished = false;
  bool fault = false;                    // e.g. model status not ok, non-finite command
  bool acknowledged = false;             // an operator acknowledged the stop (SUPERVISOR frame)
};

struct Transition {
  bool changed = false;
  Mode from = Mode::init, to = Mode::init;
  const char* reason = "";  // static string
};

class ControlStateMachine {
 public:
  explicit ControlStateMachine(double watchdog_timeout = 0.02) : timeout_(watchdog_timeout) {}
  Mode mode() const { return mode_; }
  const char* last_reason() const { return reason_; }
  double watchdog_timeout() const { return timeout_; }

  Transition step(const StateMachineInputs& in) {
    // 1 ns of slack: times are cycle counts times the period, and (k + n) T - k T may round above
    // n T; the watchdog must trip on the same cycle whatever k is.
    const bool fresh = in.have_valid_frame && (in.t - in.last_valid_frame_time) <= timeout_ + 1e-9;
    switch (mode_) {
      case Mode::init: return go(Mode::wait_sensors, "started");
      case Mode::wait_sensors:
        if (fresh) return go(Mode::hold, "first valid sensor frame");
        break;
      case Mode::hold:
      case Mode::track:
        if (!fresh) return go(Mode::safe_stop, "watchdog: sensor frames timed out");
        if (in.fault) return go(Mode::safe_stop, "fault");
        if (mode_ == Mode::hold && in.track_requested && !in.stop_requested && !in.trajectory_finished)
          return go(Mode::track, "tracking requested");
        if (mode_ == Mode::track && in.stop_requested) return go(Mode::hold, "stop requested");
        if (mode_ == Mode::track && in.trajectory_finished) return go(Mode::hold, "trajectory finished");
        break;
      case Mode::safe_stop:
        // A stop latches: frames coming back are not a person having seen it.
        if (in.acknowledged && fresh && !in.fault) return go(Mode::hold, "acknowledged, sensor frames fresh, no fault");
        break;
    }
    return Transition{false, mode_, mode_, ""};
  }

 private:
  Transition go(Mode to, const char* reason) {
    Transition t{true, mode_, to, reason};
    mode_ = to;
    reason_ = reason;
    return t;
  }
  double timeout_;
  Mode mode_ = Mode::init;
  const char* reason_ = "";
};

}  // namespace exc::safety
