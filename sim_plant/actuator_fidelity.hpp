#pragma once
// The actuator fidelities, each declared once: its name (a scene's actuators.fidelity, the benches'
// rows), its one-line description, how its actuators are built (an ActuatorDynamics), and the facts
// other code asks of it: which commands it takes, whether the machine's hydraulic circuit runs,
// whether the strokes' ends and the flow limit act, and the effort lag a law may compensate. The
// scene reader, the plant, its CAN node, the harness, the run report, the benches and the tools ask
// the entry, never the name. The shipped fidelities are registered one line each in
// actuator_fidelities.cpp at the registry's first use (an explicit list: a static library drops
// self-registering objects nothing references); a program or test adds its own with
// register_actuator_fidelity before it reads a scene. A fidelity's dynamics run every plant substep:
// nothing in them allocates.
#include <cstdint>
#include <memory>
#include <string>

#include "model/machine.hpp"
#include "settings/name_registry.hpp"
#include "sim_plant/hydraulics.hpp"

namespace exc::plant {

// The scene's `actuators:` section. The hydraulic machine's numbers are the machine file's
// (Machine::hydraulics): a scene chooses how the actuators are modelled, the machine what they are.
struct ActuatorParameters {
  std::string fidelity = "ideal";  // a registered fidelity's name
  double lag = 0.02;               // s, limited: effort time constant (0: none)
};

// What the controller sends each cycle:
//   effort  swing torque (N m) and cylinder forces (N) in 'value', positive pushes longer;
//   valve   signed spool openings -1..1 in 'value' (positive extends / swings counter-clockwise);
//   pilot   pilot pressures 0..hydraulics.pilot_full_stroke (Pa) on each spool's A end (opens
//           P->A: extends / swings counter-clockwise) and B end, as a real valve block takes them.
struct ActuatorCommand {
  enum Mode { effort, valve, pilot } mode = effort;
  Vec4 value = Vec4::Zero();
  Vec4 pilot_a = Vec4::Zero(), pilot_b = Vec4::Zero();
};
const char* to_string(ActuatorCommand::Mode m);

// A fidelity's actuators: the effort they hold on the machine and whatever state they carry. Built
// once per plant (start-up); every call below runs in the plant's step and allocates nothing.
class ActuatorDynamics {
 public:
  virtual ~ActuatorDynamics() = default;
  // Start holding the effort `hold` (the gravity-holding efforts at rest) with the machine at q_a.
  virtual void reset(const Vec4& q_a, const Vec4& hold) = 0;
  // The command of this cycle, of a mode the entry's input takes (the plant checks it first).
  virtual void set_command(const ActuatorCommand& command) = 0;
  // The effort at this instant.
  virtual Vec4 effort(const Vec4& q_a) const = 0;
  // The effort held on the machine over the next substep of length dt, from the state now.
  virtual Vec4 effort_over(double /*dt*/, const Vec4& q_a) { return effort(q_a); }
  // Advance the actuators' own states over dt with the machine's motion.
  virtual void advance(double /*dt*/, const Vec4& /*q_a*/, const Vec4& /*qd_a*/) {}
};

// Builds a fidelity's actuators for the machine. `circuit` is the machine's hydraulic circuit (with
// its hydraulics when the entry has kHydraulicCircuit, else default hydraulics kept for the cylinder
// areas of the sensors' pressure channels); it outlives the dynamics.
using ActuatorFactory = std::unique_ptr<ActuatorDynamics> (*)(const Machine& machine, const ActuatorParameters& params,
                                                               HydraulicCircuit& circuit);

// The commands a fidelity's actuators take: efforts (the paper's swing torque and cylinder forces),
// or the valves' spool openings and pilot pressures (what a real valve block takes).
enum class ActuatorInput : std::uint8_t { efforts, valves };

// What else the plant does for a fidelity (bits of ActuatorFidelityEntry::traits):
//   kHydraulicCircuit  the machine's circuit runs: its parameters are checked, the chamber pressures
//                      are state (range check, telemetry, the energy books), the seals' friction acts,
//                      the pilot supply and engine obey the safety controller, hydraulic faults apply;
//   kEndStops          a cylinder stops at its stroke's ends (without: driving through is a fault);
//   kSpeedLimits       the valves' flow limit acts as a speed limit on each function.
enum ActuatorTrait : std::uint8_t { kHydraulicCircuit = 1, kEndStops = 2, kSpeedLimits = 4 };

struct ActuatorFidelityEntry {
  std::string name;
  std::string what;
  ActuatorFactory make = nullptr;
  ActuatorInput input = ActuatorInput::efforts;
  std::uint8_t traits = 0;
  // The effort's time constant (s) that a law commanding efforts may compensate (the firmware's
  // actuator_lag); null: the fidelity has no such lag.
  double (*effort_lag)(const ActuatorParameters& params) = nullptr;

  bool has(ActuatorTrait t) const { return (traits & t) != 0; }
  bool takes_valves() const { return input == ActuatorInput::valves; }
  // Whether a command of mode m is of the kind these actuators take.
  bool takes(ActuatorCommand::Mode m) const { return takes_valves() == (m != ActuatorCommand::effort); }
};

// The factory of a fidelity whose dynamics are constructed from (machine, params, circuit).
template <class Dynamics>
std::unique_ptr<ActuatorDynamics> build_actuators(const Machine& machine, const ActuatorParameters& params,
                                                   HydraulicCircuit& circuit) {
  return std::make_unique<Dynamics>(machine, params, circuit);
}

class ActuatorFidelityRegistry : public settings::NameRegistry<ActuatorFidelityEntry> {
 public:
  ActuatorFidelityRegistry() : NameRegistry("actuator fidelity") {}
  // Throws std::invalid_argument for an empty or taken name or a missing factory.
  void add(ActuatorFidelityEntry entry);
};

// The process's fidelities: the shipped ones, then whatever was registered (before threads start).
ActuatorFidelityRegistry& actuator_fidelities();
void register_actuator_fidelity(ActuatorFidelityEntry entry);
// The entry of a scene's fidelity (std::invalid_argument naming the registered ones when unknown).
inline const ActuatorFidelityEntry& fidelity_of(const ActuatorParameters& p) { return actuator_fidelities().at(p.fidelity); }

}  // namespace exc::plant
