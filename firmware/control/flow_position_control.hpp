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
#include "control/controller_config.hpp"

namespace exc::control {

class FlowPositionControl final : public Controller {
 public:
  explicit FlowPositionControl(const ControllerConfig& config) : gains_(config.flow_kp) {}
  void reset() override {}
  ControlOutput update(const ControlInput& in) override {
    ControlOutput out;
    out.e = in.q - in.q_d;
    out.ed = in.qd - in.qd_d;
    out.velocity_command = true;
    out.velocity = in.qd_d - gains_.cwiseProduct(out.e);
    return out;
  }
  ControllerKind kind() const override { return ControllerKind::flow; }

 private:
  Vec4 gains_;
};

}  // namespace exc::control
