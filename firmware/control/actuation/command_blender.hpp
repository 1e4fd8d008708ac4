#pragma once
#include "model/types.hpp"

namespace exc::control {

// Bumpless switching of modes or controllers: at the switch the new law's command is offset to
// equal the last command sent, and the offset fades linearly to zero over blend_time. The command
// is continuous at the switch and equals the new law's after blend_time.
class CommandBlender {
 public:
  explicit CommandBlender(double blend_time = 0.2) : blend_time_(blend_time) {}
  // last_sent: the command sent on the previous cycle; first_new: the new law's command now.
  void on_switch(double t, const Vec4& last_sent, const Vec4& first_new) {
    t_switch_ = t;
    offset_ = last_sent - first_new;
    active_ = true;
  }
  Vec4 apply(double t, const Vec4& command) {
    if (!active_) return command;
    const double s = blend_time_ > 0 ? (t - t_switch_) / blend_time_ : 1.0;
    if (s >= 1) {
      active_ = false;
      return command;
    }
    return command + offset_ * (1 - (s < 0 ? 0 : s));
  }
  bool active() const { return active_; }

 private:
  double blend_time_;
  double t_switch_ = 0;
  bool active_ = false;
  Vec4 offset_ = Vec4::Zero();
};

}  // namespace exc::control
