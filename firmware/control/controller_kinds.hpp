#pragma once
// The controllers, declared once: the name a scene's controller.type and the programs' --controller
// take, and what each is. The parser, the command lines, their --help and the docs all read this
// table, so a controller added here is accepted everywhere and nowhere else.
#include <array>
#include <optional>
#include <string>

#include "control/control_types.hpp"

namespace exc::control {

struct ControllerKindEntry {
  ControllerKind kind;
  const char* name;
  const char* what;
};

inline constexpr std::array<ControllerKindEntry, 3> kControllerKinds = {{
    {ControllerKind::pid, "pid", "closed-chain inverse dynamics + PID (the paper's baseline)"},
    {ControllerKind::adaptive, "adaptive", "adaptive computed torque with the soil regressor (paper eqs. 12-28)"},
    {ControllerKind::slotine_li, "slotine_li", "Slotine-Li passivity-based adaptive law (needs no acceleration)"},
}};

inline std::optional<ControllerKind> controller_kind_named(const std::string& name) {
  for (const ControllerKindEntry& e : kControllerKinds)
    if (name == e.name) return e.kind;
  return std::nullopt;
}

// "pid, adaptive, slotine_li": for error messages and --help.
inline std::string controller_kind_names() {
  std::string s;
  for (const ControllerKindEntry& e : kControllerKinds) s += (s.empty() ? "" : ", ") + std::string(e.name);
  return s;
}

}  // namespace exc::control
