#pragma once
// The control laws, each declared once: its name (a scene's controller.type, the programs'
// --controller, the telemetry channels' suffix), its one-line description (--help, the docs), how it
// is built, and which command interfaces it can drive. The settings reader, the command lines, the
// sweeps, excavator-sim's default set and the interface check all read this registry, so a law
// registered here is accepted everywhere.
//
// The shipped laws are registered by one line each in controller_registry.cpp, at the registry's
// first use: an explicit list, not self-registering objects, which a static library would drop
// unless something referenced them. A program or test adds its own with register_controller before
// it reads a scene. Registration and creation are start-up work (they allocate); the loop only
// calls the built Controller.
#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <type_traits>

#include "control/controller_config.hpp"
#include "control/laws/effort_limits.hpp"
#include "control/task/task.hpp"
#include "model/model.hpp"
#include "settings/name_registry.hpp"

namespace exc::control {

// Builds the law with the scene's controller settings. The model outlives the controller.
using ControllerFactory = std::unique_ptr<Controller> (*)(const Model& model, const ControllerConfig& config);

// The command interfaces a law can drive (bits of CommandInterface). An effort law drives both: on the
// valve interface the valve stage turns its efforts into openings. A flow law commands velocities,
// which only the valve stage can carry.
enum InterfaceSet : std::uint8_t { kEffortInterface = 1, kValveInterface = 2, kAnyInterface = 3 };

// Whether excavator-sim runs the law when a scene names none (the paper's comparison and, on a
// valve-commanded machine, the industry's baseline).
enum class DefaultRun : std::uint8_t { no, yes };

// Whether the law adapts parameter estimates at controller.adaptation_rate (what a sweep's
// adaptation_scale changes; the stability map leaves a law that adapts nothing out of that axis).
enum class Adapts : std::uint8_t { no, yes };

struct ControllerEntry {
  std::string name;
  std::string what;
  ControllerFactory make = nullptr;
  std::uint8_t interfaces = kAnyInterface;
  DefaultRun default_run = DefaultRun::no;
  Adapts adapts = Adapts::no;
  // Why the law cannot run this task ("" when it can; null: it can run any task). A default set
  // leaves such a law out and says why; asked for by name it still runs.
  std::string (*task_misfit)(const Task& task) = nullptr;
};

// The factory of a law whose constructor takes (model, config, effort limits) or (config) alone: a
// program's or a test's own law may take the whole ControllerConfig; the shipped laws take their own
// settings, ControllerConfig's members whole, each through its factory in controller_registry.cpp.
template <typename Law>
std::unique_ptr<Controller> build_law(const Model& model, const ControllerConfig& config);

class ControllerRegistry : public settings::NameRegistry<ControllerEntry> {
 public:
  ControllerRegistry() : NameRegistry("controller") {}
  // Throws std::invalid_argument for an empty or taken name, a missing factory or no interface.
  void add(ControllerEntry entry);
  // The telemetry's controller number (command_t, controller_state_t): the registration index, so the
  // shipped laws keep the numbers logs already carry (pid 0, adaptive 1, slotine_li 2, flow 3).
  std::int8_t id_of(std::string_view name) const { return static_cast<std::int8_t>(index_of(name)); }
};

// The process's registry: the shipped laws, then whatever was registered. Not thread-safe to add to:
// register before threads start.
ControllerRegistry& controller_registry();
void register_controller(ControllerEntry entry);

// Builds the named law (std::invalid_argument for an unknown name).
std::unique_ptr<Controller> make_controller(std::string_view name, const Model& model, const ControllerConfig& config);

// Why the named law cannot drive `interface` ("" when it can), as a person reads it.
std::string interface_misfit(const ControllerEntry& law, CommandInterface interface);

template <typename Law>
std::unique_ptr<Controller> build_law(const Model& model, const ControllerConfig& config) {
  if constexpr (std::is_constructible_v<Law, const Model&, const ControllerConfig&, const EffortLimits&>)
    return std::make_unique<Law>(model, config, effort_limits_of(model.machine));
  else
    return std::make_unique<Law>(config);
}

}  // namespace exc::control
