#pragma once
// The faults a run can inject (the fault campaign, excavator-plant --stuck-spool): one enumeration
// for every end that acts on them. The plant's node acts on the machine's own (sensors, actuators,
// spools, pressure transmitters, its controller's fault); the lockstep run on the rest (the bus,
// the soil, the pumps, the operator station).
#include <cstdint>

#include "settings/enum_table.hpp"

namespace exc::plant {

enum class FaultKind : std::uint8_t {
  none, bus_burst, sensor_freeze, sensor_jump, actuator_loss, actuator_jam, rock, pump_loss, spool_stuck,
  pressure_stuck, pressure_jump, pressure_drift, operator_stop, machine_fault, operator_link_lost
};
// By name (a sweep spec's `faults:`); to_string adds "none".
inline constexpr settings::EnumTable<FaultKind, 14> kFaultKinds{{{
    {FaultKind::bus_burst, "bus_burst", "dropped, corrupted and delayed frames at both ends"},
    {FaultKind::sensor_freeze, "sensor_freeze", "a sensor holds its reading"},
    {FaultKind::sensor_jump, "sensor_jump", "a sensor reading jumps by an offset"},
    {FaultKind::actuator_loss, "actuator_loss", "an actuator loses a fraction of its effort"},
    {FaultKind::actuator_jam, "actuator_jam", "an actuator jams"},
    {FaultKind::rock, "rock", "the soil 5-50x stiffer"},
    {FaultKind::pump_loss, "pump_loss", "the hydraulic machine's pumps lose a fraction of their flow"},
    {FaultKind::spool_stuck, "spool_stuck", "a main-valve spool sticks at an opening (the hydraulic machine)"},
    {FaultKind::pressure_stuck, "pressure_stuck", "a chamber pressure sensor holds its reading (the hydraulic machine)"},
    {FaultKind::pressure_jump, "pressure_jump", "a chamber pressure reading steps by an offset (the hydraulic machine)"},
    {FaultKind::pressure_drift, "pressure_drift", "a chamber pressure reading drifts out of range (the hydraulic machine)"},
    {FaultKind::operator_stop, "operator_stop", "the operator station sends a SUPERVISOR stop at the fault's start"},
    {FaultKind::machine_fault, "machine_fault", "the machine's own controller reports a fault (PlantFaults) and holds"},
    {FaultKind::operator_link_lost, "operator_link_lost",
     "the operator station's keep-alive (SUPERVISOR none every 0.1 s from 0.1 s) ends at the fault's start"},
}}};
inline const char* to_string(FaultKind kind) { return kind == FaultKind::none ? "none" : kFaultKinds.name_of(kind); }

// A fault injected into the simulated machine: what a real machine's sensor or actuator can do while
// the firmware cannot tell from the frames alone. The plant's node acts on sensor_freeze,
// sensor_jump, actuator_loss, actuator_jam, spool_stuck, the pressure transmitters' three and
// machine_fault (its controller reports a fault, PlantFaults bit 1, and holds its valves centred
// while it lasts: an ECU's pump or oil-temperature fault); on the others it does nothing.
struct InjectedFault {
  using Kind = FaultKind;
  Kind kind = Kind::none;
  int joint = 0;    // sensor and actuator faults: 0 swing .. 3 bucket
  int chamber = 0;  // pressure faults: 0 side A (bore, port A), 1 side B
  // sensor_jump: offset (m or rad); actuator_loss: fraction of effort lost; spool_stuck: the spool
  // position (-1..1) it sticks at, whatever is commanded (the hydraulic plant's circuit holds it);
  // pressure_jump: offset (Pa); pressure_drift: rate (Pa/s); rock: soil stiffness x; pump_loss:
  // fraction of the pumps' flow lost; bus_burst: fraction of frames damaged.
  double magnitude = 0;
};

}  // namespace exc::plant
