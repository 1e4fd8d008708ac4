#pragma once
// Each consumer's part of the controller's settings. The scene's reader (and the settings blob) fill
// one ControllerConfig; each law takes its own settings struct, declared in its room, never the whole
// ControllerConfig, and so do the actuation stage and the path's clock, so that the rooms of control/
// stand on one another as floors and none includes this folder's top (docs/architecture.md, include
// rules). The registry's factories hand each shipped law its part here, the firmware's control step
// and node the stage's and the clock's. Start-up code: copies, no allocation.
#include "control/actuation/actuation_stage.hpp"
#include "control/controller_config.hpp"
#include "control/laws/adaptive_law_settings.hpp"
#include "control/laws/computed_torque_pid.hpp"
#include "control/laws/flow_position_control.hpp"
#include "control/laws/slotine_li.hpp"
#include "control/task/path_clock.hpp"

namespace exc::control {

PidLawSettings pid_law_settings(const ControllerConfig& c);
AdaptiveLawSettings adaptive_law_settings(const ControllerConfig& c);
SlotineLiSettings slotine_li_settings(const ControllerConfig& c);
FlowLawSettings flow_law_settings(const ControllerConfig& c);
ActuationSettings actuation_settings(const ControllerConfig& c);
PathClockSettings path_clock_settings(const ControllerConfig& c);

}  // namespace exc::control
