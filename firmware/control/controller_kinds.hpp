#pragma once
// The controllers, declared once: the name a scene's controller.type and the programs' --controller
// take, and what each is. The parser, the command lines, their --help and the docs all read this
// table, so a controller added here is accepted everywhere and nowhere else.
#include "control/control_types.hpp"
#include "settings/enum_table.hpp"

namespace exc::control {

inline constexpr settings::EnumTable<ControllerKind, 4> kControllerKinds{{{
    {ControllerKind::pid, "pid", "closed-chain inverse dynamics + PID (the paper's baseline)"},
    {ControllerKind::adaptive, "adaptive", "adaptive computed torque with the soil regressor (paper eqs. 12-28)"},
    {ControllerKind::slotine_li, "slotine_li", "Slotine-Li passivity-based adaptive law (needs no acceleration)"},
    {ControllerKind::flow, "flow",
     "flow-based position control: valve flow from the desired velocity plus position feedback, no model (the "
     "industry's baseline; valve-commanded machines only)"},
}}};

}  // namespace exc::control
