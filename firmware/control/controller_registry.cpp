// The shipped control laws, one line each, and the registry that holds them.
#include "control/controller_registry.hpp"

#include <stdexcept>

#include "control/laws/adaptive_computed_torque.hpp"
#include "control/laws/computed_torque_pid.hpp"
#include "control/laws/flow_position_control.hpp"
#include "control/laws/slotine_li.hpp"

namespace exc::control {
namespace {

// The shipped laws' factories: each law built from its own members of the settings, whole, and the
// loop's period.
std::unique_ptr<Controller> make_pid(const Model& model, const ControllerConfig& config) {
  return std::make_unique<ComputedTorquePid>(model, config.pid, config.period, effort_limits_of(model.machine));
}
std::unique_ptr<Controller> make_adaptive(const Model& model, const ControllerConfig& config) {
  return std::make_unique<AdaptiveComputedTorque>(model, adaptive_law_settings(config), config.period,
                                                  effort_limits_of(model.machine));
}
std::unique_ptr<Controller> make_slotine_li(const Model& model, const ControllerConfig& config) {
  return std::make_unique<SlotineLi>(model, config.slotine_li, config.soil_parameters, config.period,
                                     effort_limits_of(model.machine));
}
std::unique_ptr<Controller> make_flow(const Model&, const ControllerConfig& config) {
  return std::make_unique<FlowPositionControl>(config.flow);
}

std::string flow_task_misfit(const Task& task) {
  return flow_law_fits(task) ? "" : "the task moves the swing, which flow-based control cannot accelerate (docs/control.md)";
}

// Their order is their telemetry number (ControllerRegistry::id_of): add new laws at the end.
ControllerRegistry shipped_controllers() {
  ControllerRegistry r;
  r.add({"pid", "closed-chain inverse dynamics + PID (the paper's baseline)", make_pid,
         kAnyInterface, DefaultRun::yes});
  r.add({"adaptive", "adaptive computed torque with the soil regressor (paper eqs. 12-28)",
         make_adaptive, kAnyInterface, DefaultRun::yes, Adapts::yes});
  r.add({"slotine_li", "Slotine-Li passivity-based adaptive law (needs no acceleration)", make_slotine_li,
         kAnyInterface, DefaultRun::no, Adapts::yes});
  r.add({"flow",
         "flow-based position control: valve flow from the desired velocity plus position feedback, no model (the "
         "industry's baseline; valve-commanded machines only)",
         make_flow, kValveInterface, DefaultRun::yes, Adapts::no, flow_task_misfit});
  return r;
}

}  // namespace

void ControllerRegistry::add(ControllerEntry entry) {
  if (!entry.make) throw std::invalid_argument("controller '" + entry.name + "' has no factory");
  if ((entry.interfaces & kAnyInterface) == 0)
    throw std::invalid_argument("controller '" + entry.name + "' drives no command interface");
  // The telemetry carries the number in an int8.
  if (entries().size() >= 127) throw std::invalid_argument("controller '" + entry.name + "': 127 laws at most");
  NameRegistry::add(std::move(entry));
}

ControllerRegistry& controller_registry() {
  static ControllerRegistry registry = shipped_controllers();
  return registry;
}

void register_controller(ControllerEntry entry) { controller_registry().add(std::move(entry)); }

std::unique_ptr<Controller> make_controller(std::string_view name, const Model& model, const ControllerConfig& config) {
  return controller_registry().at(name).make(model, config);
}

std::string interface_misfit(const ControllerEntry& law, CommandInterface interface) {
  const auto bit = interface == CommandInterface::valve ? kValveInterface : kEffortInterface;
  if (law.interfaces & bit) return "";
  return law.interfaces & kValveInterface ? law.name + " commands the valves' flow: it needs command_interface: valve"
                                          : law.name + " commands efforts: it needs command_interface: effort";
}

}  // namespace exc::control
