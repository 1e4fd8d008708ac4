#pragma once
// Builds the controller a config names, with the machine's effort limits (start-up: allocates).
#include <memory>

#include "control/adaptive_computed_torque.hpp"
#include "control/computed_torque_pid.hpp"
#include "control/flow_position_control.hpp"
#include "control/slotine_li.hpp"

namespace exc::control {

inline EffortLimits effort_limits_of(const Machine& machine) {
  EffortLimits l;
  l.min = machine.effort_min();
  l.max = machine.effort_max();
  return l;
}

inline std::unique_ptr<Controller> make_controller(ControllerKind kind, const Model& model,
                                                   const ControllerConfig& config) {
  const EffortLimits limits = effort_limits_of(model.machine);
  switch (kind) {
    case ControllerKind::pid: return std::make_unique<ComputedTorquePid>(model, config, limits);
    case ControllerKind::adaptive: return std::make_unique<AdaptiveComputedTorque>(model, config, limits);
    case ControllerKind::slotine_li: return std::make_unique<SlotineLi>(model, config, limits);
    case ControllerKind::flow: return std::make_unique<FlowPositionControl>(config);
  }
  return nullptr;
}

}  // namespace exc::control
