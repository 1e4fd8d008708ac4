#pragma once
// Flow-based position control, the industry's baseline for hydraulic machines (hydraulics.md, "How
// published automation closes the loop"): each function's valve passes the flow of the desired
// velocity plus a proportional correction of the position error,
//   u = qd_d - K_p e      (m/s; swing rad/s), e = q_a - q_d,
// and the valve stage (valve_inner_loop.hpp) turns u into an opening through the inverse orifice map
// with the measured pressures and the dead-zone compensation. No dynamic model, no force loop: a
// pressure-compensated valve makes each cylinder close to a velocity source, and that is all it
// relies on. K_p stays below a third of the oil column's frequency (2-3 Hz for the boom). Where the
// load is an inertia that the flow alone cannot accelerate (the swing), the pressure rises to the
// reliefs and the function lags: the limit of the method. Allocation-free.
#include <algorithm>
#include <cmath>

#include "control/control_types.hpp"
#include "control/task/task.hpp"

namespace exc::control {

// Where the law cannot work: a task that moves the swing (by more than 1 mrad from where it starts).
// The swing is an inertia on the softest oil column of the machine (10 L a side: it rings at 0.4 Hz);
// a flow command builds the pressure that accelerates it only once the position has fallen behind,
// so the swing lags and is stopped by the tracking fault (docs/control.md). Programs leave the law
// out of their default set for such a task and say why.
inline bool flow_law_fits(const Task& task) {
  Vec4 q0, q, qd, qdd;
  task.trajectory.evaluate(task.start_time(), q0, qd, qdd);
  for (double t = task.start_time(); t <= task.end_time(); t += 0.01) {
    task.trajectory.evaluate(t, q, qd, qdd);
    if (std::abs(q[0] - q0[0]) > 1e-3) return false;
  }
  return true;
}

// The law's own settings (controller.flow; ControllerConfig's `flow` member).
struct FlowLawSettings {
  // 1/s: position gains, u = qd_d - kp e. 2 rad/s keeps the position loop below a third of the
  // boom's 2-3 Hz oil column (hydraulics.md).
  Vec4 kp = Vec4::Constant(2);
};
// The settings blob's field list (app/settings_blob.hpp): a field added above is added here too.
template <typename Visitor>
void visit_fields(Visitor& v, FlowLawSettings& s) {
  v("kp", s.kp);
}

class FlowPositionControl final : public Controller {
 public:
  explicit FlowPositionControl(const FlowLawSettings& settings) : gains_(settings.kp) {}
  void reset() override {}
  ControlOutput update(const ControlInput& in) override {
    ControlOutput out;
    out.e = in.q - in.q_d;
    out.ed = in.qd - in.qd_d;
    out.velocity_command = true;
    out.velocity = in.qd_d - gains_.cwiseProduct(out.e);
    return out;
  }

 private:
  Vec4 gains_;
};

}  // namespace exc::control
