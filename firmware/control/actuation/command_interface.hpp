#pragma once
// What the firmware commands on the bus, the actuation stage's choice (actuation_stage.hpp): the
// efforts (a force-commanded machine, the paper's) or the valves of a hydraulic machine through the
// valve stage (valve_inner_loop.hpp). The scene's controller.command_interface.
#include <cstdint>

#include "settings/enum_table.hpp"

namespace exc::control {

enum class CommandInterface : std::uint8_t { effort = 0, valve = 1 };
inline constexpr settings::EnumTable<CommandInterface, 2> kCommandInterfaces{{{
    {CommandInterface::effort, "effort", "swing torque and cylinder forces (CMD_EFFORT): force-commanded actuators"},
    {CommandInterface::valve, "valve",
     "pilot pressures per spool end (CMD_PILOT) from the valve stage: a hydraulic machine's main valves"},
}}};

}  // namespace exc::control
