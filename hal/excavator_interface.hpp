#pragma once
// What the firmware and the plant exchange, as plain state and command interfaces (ros2_control
// style): the controllers see these structs, never a CAN frame. Axis order everywhere: swing, boom,
// arm, bucket.
#include <array>
#include <cstdint>

namespace exc::hal {

inline constexpr int kAxisCount = 4;
inline constexpr int kPumpCount = 2;
enum Axis : int { kSwing = 0, kBoom = 1, kArm = 2, kBucket = 3 };

// SENS_MACHINE's and PLANT_HEARTBEAT's PlantState, bit by bit (the machine's safety controller's
// feedback, docs/safety.md): holding (valves centred or braked, commands ignored), pilot supply cut,
// engine stopped (its run-down begun), load-holding valves closed.
inline constexpr std::uint8_t kPlantStateHolding = 1;
inline constexpr std::uint8_t kPlantStatePilotCut = 2;
inline constexpr std::uint8_t kPlantStateEngineStopped = 4;
inline constexpr std::uint8_t kPlantStateHoldingValvesClosed = 8;

// An operator station's command (SUPERVISOR's Command signal): a keep-alive, start, stop, acknowledge.
enum class SupervisorCommand : std::uint8_t { none = 0, start = 1, stop = 2, acknowledge = 3 };

struct SensorState {
  std::array<double, kAxisCount> position{};  // swing angle (rad); cylinder pin-to-pin lengths (m)
  std::array<double, kAxisCount> velocity{};  // swing rate (rad/s); cylinder stroke rates (m/s)
  // Chamber pressures (Pa): swing motor port A / B; cylinder cap (bore) side A / rod side B.
  std::array<double, kAxisCount> pressure_a{};
  std::array<double, kAxisCount> pressure_b{};
  std::array<double, kPumpCount> pump_pressure{};  // Pa
  // Main-valve spool positions as their LVDTs measure them, -1..1 of the stroke from neutral
  // (positive towards positive motion); hydraulic plant only, like the pressures.
  std::array<double, kAxisCount> spool{};
  // The pressures are measured (the hydraulic plant); false for the force-commanded fidelities.
  // Plant: what it sends; firmware: what the last sensor frame said.
  bool pressure_valid = false;
  std::uint8_t plant_state = 0;   // kPlantState* bits
  std::uint8_t plant_faults = 0;  // plant fault bits
  std::uint8_t plant_heartbeat_state = 0;  // firmware side: PlantState of the last plant heartbeat
  std::uint64_t cycle = 0;        // plant: the SYNC cycle this answers; firmware: cycle of the last complete set
  bool motion_valid = false;      // firmware side: every value belongs to `cycle`
  bool plant_emergency = false;       // firmware side: the plant latched an emergency stop
  std::uint16_t plant_fault_code = 0;
  // Firmware side: SUPERVISOR commands received and not yet taken, bit 1 << SupervisorCommand
  // (none: a keep-alive, start, stop, acknowledge); the taker clears them.
  std::uint8_t supervisor_pending = 0;
};

// Every double of a sensor set, by name, to a state visitor (control::StateVisitor's shape: the
// firmware's scan for subnormal numbers, docs/floating-point.md). A template, so hal includes nothing
// of ours. A double member added above and left out here fails `firmware/visit_state visits every
// double of hal::SensorState once`.
template <typename Visitor>
void visit_state(const SensorState& s, Visitor& v) {
  v.visit("sensors position", s.position);
  v.visit("sensors velocity", s.velocity);
  v.visit("sensors pressure_a", s.pressure_a);
  v.visit("sensors pressure_b", s.pressure_b);
  v.visit("sensors pump_pressure", s.pump_pressure);
  v.visit("sensors spool", s.spool);
}

// The three exclusive command sets (DBC ExcCommandSet): efforts, signed valve openings, or pilot
// pressures on both ends of each main-valve spool.
enum class CommandMode : std::uint8_t { effort, valve, pilot };

struct CommandState {
  CommandMode mode = CommandMode::effort;
  // effort: swing torque (N m), cylinder forces (N, extending positive); valve: openings in -1..1.
  std::array<double, kAxisCount> value{};
  // pilot: pressure on the spool's A end (opens towards positive motion) and B end, Pa.
  std::array<double, kAxisCount> pilot_a{};
  std::array<double, kAxisCount> pilot_b{};
  std::uint8_t firmware_mode = 0;  // firmware state machine, 0..15 (from its heartbeat)
  std::uint64_t cycle = 0;         // the cycle these commands were computed in
  bool valid = false;              // plant side: a complete command set has been received
  bool emergency_stop = false;     // plant side: the firmware latched an emergency stop
  std::uint16_t fault_code = 0;
};

// Every double of a command set (as visit_state(SensorState) above; held to the struct by
// `firmware/visit_state visits every double of hal::CommandState once`).
template <typename Visitor>
void visit_state(const CommandState& c, Visitor& v) {
  v.visit("command value", c.value);
  v.visit("command pilot_a", c.pilot_a);
  v.visit("command pilot_b", c.pilot_b);
}

}  // namespace exc::hal
