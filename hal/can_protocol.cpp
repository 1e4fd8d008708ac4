#include "hal/can_protocol.hpp"

namespace exc::hal {
namespace {

// Layout shared by every frame: a 4-bit rolling counter first, a CRC-8 in the last byte.
constexpr SignalSpec counter_signal{"Counter", 0, 4, false, 1, 0, 0, 15, ""};
constexpr SignalSpec crc_at(int length) { return {"Crc", static_cast<std::uint16_t>(8 * (length - 1)), 8, false, 1, 0, 0, 255, ""}; }

constexpr SignalSpec fw_emergency[] = {
    counter_signal,
    {"EmergencyStop", 4, 1, false, 1, 0, 0, 1, ""},
    {"FaultCode", 8, 16, false, 1, 0, 0, 65535, ""},
    crc_at(4)};
constexpr SignalSpec plant_emergency[] = {
    counter_signal,
    {"EmergencyStop", 4, 1, false, 1, 0, 0, 1, ""},
    {"FaultCode", 8, 16, false, 1, 0, 0, 65535, ""},
    crc_at(4)};
// An operator's command (SupervisorCommand); ranked just below the two emergency frames.
constexpr SignalSpec supervisor[] = {
    counter_signal, {"Command", 4, 4, false, 1, 0, 0, 3, ""}, crc_at(2)};
constexpr SignalSpec sync[] = {
    counter_signal,
    {"Cycle", 4, 20, false, 1, 0, 0, 1048575, ""},
    crc_at(4)};
// Efforts: 16-bit two's complement; 4 N m and 25 N per bit cover +-70 kN m and +-800 kN.
constexpr SignalSpec cmd_effort[] = {
    counter_signal,
    {"SwingTorque", 8, 16, true, 4, 0, -70000, 70000, "N.m"},
    {"BoomForce", 24, 16, true, 25, 0, -800000, 800000, "N"},
    {"ArmForce", 40, 16, true, 25, 0, -800000, 800000, "N"},
    {"BucketForce", 56, 16, true, 25, 0, -800000, 800000, "N"},
    crc_at(12)};
constexpr SignalSpec cmd_valve[] = {
    counter_signal,
    {"SwingValve", 4, 12, true, 0.0005, 0, -1, 1, ""},
    {"BoomValve", 16, 12, true, 0.0005, 0, -1, 1, ""},
    {"ArmValve", 28, 12, true, 0.0005, 0, -1, 1, ""},
    {"BucketValve", 40, 12, true, 0.0005, 0, -1, 1, ""},
    crc_at(8)};
// Pilot pressures per spool end: 12 bits at 2 kPa cover 0..8.19 MPa (real pilots: 0-5 MPa).
#define EXC_PILOT_PAIR(prefix, start)                                         \
  {prefix "PilotA", start, 12, false, 2000, 0, 0, 8190000, "Pa"},             \
  {prefix "PilotB", start + 12, 12, false, 2000, 0, 0, 8190000, "Pa"}
constexpr SignalSpec cmd_pilot[] = {
    counter_signal,
    EXC_PILOT_PAIR("Swing", 4),
    EXC_PILOT_PAIR("Boom", 28),
    EXC_PILOT_PAIR("Arm", 52),
    EXC_PILOT_PAIR("Bucket", 76),
    crc_at(16)};
#undef EXC_PILOT_PAIR
// The machine's sensors of one cycle. Swing angle 24 bits at 1 urad, rates 16 bits at 0.1 mrad/s and
// 0.1 mm/s; cylinder lengths 20 bits at 10 um cover 0..10.49 m (any machine); pressures 16 bits at
// 1 kPa cover 0..65.5 MPa (relief 34.3 MPa, port reliefs 36.8 MPa).
#define EXC_CYLINDER(prefix, start)                                           \
  {prefix "Length", start, 20, false, 1e-5, 0, 0, 10.48575, "m"},             \
  {prefix "Rate", start + 20, 16, true, 1e-4, 0, -3.2768, 3.2767, "m/s"}
#define EXC_PRESSURE(name, start) {name, start, 16, false, 1000, 0, 0, 65535000, "Pa"}
// Spool positions 12 bits at 0.1 % of the stroke (an LVDT's resolution on a valve actuator; the spool
// lies in -1..1 of its stroke, the range leaves room to report a reading beyond it).
#define EXC_SPOOL(name, start) {name, start, 12, true, 1e-3, 0, -2.048, 2.047, ""}
constexpr SignalSpec sens_machine[] = {
    counter_signal,
    {"PlantState", 4, 4, false, 1, 0, 0, 15, ""},
    {"SwingAngle", 8, 24, true, 1e-6, 0, -8.388608, 8.388607, "rad"},
    {"SwingRate", 32, 16, true, 1e-4, 0, -3.2768, 3.2767, "rad/s"},
    {"PlantFaults", 48, 8, false, 1, 0, 0, 255, ""},
    EXC_CYLINDER("Boom", 56),
    EXC_CYLINDER("Arm", 92),
    EXC_CYLINDER("Bucket", 128),
    {"PressureValid", 164, 1, false, 1, 0, 0, 1, ""},
    EXC_PRESSURE("SwingPressureA", 168),
    EXC_PRESSURE("SwingPressureB", 184),
    EXC_PRESSURE("BoomPressureA", 200),
    EXC_PRESSURE("BoomPressureB", 216),
    EXC_PRESSURE("ArmPressureA", 232),
    EXC_PRESSURE("ArmPressureB", 248),
    EXC_PRESSURE("BucketPressureA", 264),
    EXC_PRESSURE("BucketPressureB", 280),
    EXC_PRESSURE("Pump1Pressure", 296),
    EXC_PRESSURE("Pump2Pressure", 312),
    EXC_SPOOL("SwingSpool", 328),
    EXC_SPOOL("BoomSpool", 340),
    EXC_SPOOL("ArmSpool", 352),
    EXC_SPOOL("BucketSpool", 364),
    crc_at(48)};
#undef EXC_CYLINDER
#undef EXC_PRESSURE
#undef EXC_SPOOL
constexpr SignalSpec fw_heartbeat[] = {
    counter_signal, {"FirmwareMode", 4, 4, false, 1, 0, 0, 15, ""}, crc_at(2)};
constexpr SignalSpec plant_heartbeat[] = {
    counter_signal, {"PlantState", 4, 4, false, 1, 0, 0, 15, ""}, crc_at(2)};

template <std::size_t N>
constexpr std::uint8_t count_of(const SignalSpec (&)[N]) {
  static_assert(N - 2 <= kMaxDataSignals, "kMaxDataSignals must hold every message's data signals");
  return static_cast<std::uint8_t>(N);
}

// Every frame is CAN FD with bit-rate switch (excavator.dbc: VFrameFormat, CANFD_BRS).
const std::array<MessageSpec, kMessageCount> kMessages{{
    {"FW_EMERGENCY", can_id::fw_emergency, 4, true, true, Node::firmware, 0, CommandSet::none, fw_emergency, count_of(fw_emergency)},
    {"PLANT_EMERGENCY", can_id::plant_emergency, 4, true, true, Node::plant, 0, CommandSet::none, plant_emergency, count_of(plant_emergency)},
    {"SUPERVISOR", can_id::supervisor, 2, true, true, Node::operator_station, 0, CommandSet::none, supervisor, count_of(supervisor)},
    {"SYNC", can_id::sync, 4, true, true, Node::firmware, 1, CommandSet::none, sync, count_of(sync)},
    {"CMD_EFFORT", can_id::cmd_effort, 12, true, true, Node::firmware, 1, CommandSet::effort, cmd_effort, count_of(cmd_effort)},
    {"CMD_VALVE", can_id::cmd_valve, 8, true, true, Node::firmware, 1, CommandSet::valve, cmd_valve, count_of(cmd_valve)},
    {"CMD_PILOT", can_id::cmd_pilot, 16, true, true, Node::firmware, 1, CommandSet::pilot, cmd_pilot, count_of(cmd_pilot)},
    {"SENS_MACHINE", can_id::sens_machine, 48, true, true, Node::plant, 1, CommandSet::none, sens_machine, count_of(sens_machine)},
    {"FW_HEARTBEAT", can_id::fw_heartbeat, 2, true, true, Node::firmware, 100, CommandSet::none, fw_heartbeat, count_of(fw_heartbeat)},
    {"PLANT_HEARTBEAT", can_id::plant_heartbeat, 2, true, true, Node::plant, 100, CommandSet::none, plant_heartbeat, count_of(plant_heartbeat)},
}};

}  // namespace

const std::array<MessageSpec, kMessageCount>& protocol_messages() { return kMessages; }

const char* to_string(Node node) {
  switch (node) {
    case Node::firmware: return "Firmware";
    case Node::plant: return "Plant";
    case Node::operator_station: return "Operator";
  }
  return "?";
}

const char* to_string(SupervisorCommand command) {
  switch (command) {
    case SupervisorCommand::none: return "none";
    case SupervisorCommand::start: return "start";
    case SupervisorCommand::stop: return "stop";
    case SupervisorCommand::acknowledge: return "acknowledge";
  }
  return "?";
}

int message_index(std::uint32_t id) {
  for (std::size_t i = 0; i < kMessages.size(); ++i) {
    if (kMessages[i].id == id) return static_cast<int>(i);
  }
  return -1;
}

const MessageSpec* find_message(std::uint32_t id) {
  const int i = message_index(id);
  return i < 0 ? nullptr : &kMessages[static_cast<std::size_t>(i)];
}

}  // namespace exc::hal
