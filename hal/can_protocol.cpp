#include "hal/can_protocol.hpp"

namespace exc::hal {
namespace {

// Layout shared by every frame: a 4-bit rolling counter first, a CRC-8 in the last byte.
constexpr SignalSpec counter_signal{"Counter", 0, 4, false, 1, 0, 0, 15, ""};
constexpr SignalSpec crc_at(std::uint8_t dlc) { return {"Crc", static_cast<std::uint8_t>(8 * (dlc - 1)), 8, false, 1, 0, 0, 255, ""}; }

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
constexpr SignalSpec sync[] = {
    counter_signal,
    {"Cycle", 4, 20, false, 1, 0, 0, 1048575, ""},
    crc_at(4)};
// Efforts: 16-bit two's complement; 4 N m and 25 N per bit cover +-70 kN m and +-800 kN.
constexpr SignalSpec cmd_effort_a[] = {
    counter_signal,
    {"SwingTorque", 8, 16, true, 4, 0, -70000, 70000, "N.m"},
    {"BoomForce", 24, 16, true, 25, 0, -800000, 800000, "N"},
    crc_at(6)};
constexpr SignalSpec cmd_effort_b[] = {
    counter_signal,
    {"ArmForce", 8, 16, true, 25, 0, -800000, 800000, "N"},
    {"BucketForce", 24, 16, true, 25, 0, -800000, 800000, "N"},
    crc_at(6)};
constexpr SignalSpec cmd_valve[] = {
    counter_signal,
    {"SwingValve", 4, 12, true, 0.0005, 0, -1, 1, ""},
    {"BoomValve", 16, 12, true, 0.0005, 0, -1, 1, ""},
    {"ArmValve", 28, 12, true, 0.0005, 0, -1, 1, ""},
    {"BucketValve", 40, 12, true, 0.0005, 0, -1, 1, ""},
    crc_at(8)};
constexpr SignalSpec sens_swing[] = {
    counter_signal,
    {"PlantState", 4, 4, false, 1, 0, 0, 15, ""},
    {"SwingAngle", 8, 24, true, 1e-6, 0, -8.388608, 8.388607, "rad"},
    {"SwingRate", 32, 16, true, 1e-4, 0, -3.2768, 3.2767, "rad/s"},
    {"PlantFaults", 48, 8, false, 1, 0, 0, 255, ""},
    crc_at(8)};
// Cylinders: 20-bit length at 10 um covers 0..10.49 m (any machine); 16-bit rate at 0.1 mm/s.
#define EXC_CYLINDER_SENSOR(prefix)                                             \
  {counter_signal,                                                              \
   {prefix "Length", 4, 20, false, 1e-5, 0, 0, 10.48575, "m"},                  \
   {prefix "Rate", 24, 16, true, 1e-4, 0, -3.2768, 3.2767, "m/s"},              \
   crc_at(6)}
constexpr SignalSpec sens_boom[] = EXC_CYLINDER_SENSOR("Boom");
constexpr SignalSpec sens_arm[] = EXC_CYLINDER_SENSOR("Arm");
constexpr SignalSpec sens_bucket[] = EXC_CYLINDER_SENSOR("Bucket");
#undef EXC_CYLINDER_SENSOR
// Pressures: 12 bits at 0.01 MPa cover 0..40.95 MPa (relief is 34.3 MPa).
#define EXC_PRESSURE_SENSOR(prefix)                                             \
  {counter_signal,                                                              \
   {prefix "PressureA", 4, 12, false, 10000, 0, 0, 40950000, "Pa"},             \
   {prefix "PressureB", 16, 12, false, 10000, 0, 0, 40950000, "Pa"},            \
   crc_at(5)}
constexpr SignalSpec sens_pressure_boom[] = EXC_PRESSURE_SENSOR("Boom");
constexpr SignalSpec sens_pressure_arm[] = EXC_PRESSURE_SENSOR("Arm");
constexpr SignalSpec sens_pressure_bucket[] = EXC_PRESSURE_SENSOR("Bucket");
#undef EXC_PRESSURE_SENSOR
constexpr SignalSpec fw_heartbeat[] = {
    counter_signal, {"FirmwareMode", 4, 4, false, 1, 0, 0, 15, ""}, crc_at(2)};
constexpr SignalSpec plant_heartbeat[] = {
    counter_signal, {"PlantState", 4, 4, false, 1, 0, 0, 15, ""}, crc_at(2)};

template <std::size_t N>
constexpr std::uint8_t count_of(const SignalSpec (&)[N]) { return static_cast<std::uint8_t>(N); }

const std::array<MessageSpec, kMessageCount> kMessages{{
    {"FW_EMERGENCY", can_id::fw_emergency, 4, Node::firmware, 0, CommandSet::none, fw_emergency, count_of(fw_emergency)},
    {"PLANT_EMERGENCY", can_id::plant_emergency, 4, Node::plant, 0, CommandSet::none, plant_emergency, count_of(plant_emergency)},
    {"SYNC", can_id::sync, 4, Node::firmware, 1, CommandSet::none, sync, count_of(sync)},
    {"CMD_EFFORT_A", can_id::cmd_effort_a, 6, Node::firmware, 1, CommandSet::effort, cmd_effort_a, count_of(cmd_effort_a)},
    {"CMD_EFFORT_B", can_id::cmd_effort_b, 6, Node::firmware, 1, CommandSet::effort, cmd_effort_b, count_of(cmd_effort_b)},
    {"CMD_VALVE", can_id::cmd_valve, 8, Node::firmware, 1, CommandSet::valve, cmd_valve, count_of(cmd_valve)},
    {"SENS_SWING", can_id::sens_swing, 8, Node::plant, 1, CommandSet::none, sens_swing, count_of(sens_swing)},
    {"SENS_BOOM", can_id::sens_boom, 6, Node::plant, 1, CommandSet::none, sens_boom, count_of(sens_boom)},
    {"SENS_ARM", can_id::sens_arm, 6, Node::plant, 1, CommandSet::none, sens_arm, count_of(sens_arm)},
    {"SENS_BUCKET", can_id::sens_bucket, 6, Node::plant, 1, CommandSet::none, sens_bucket, count_of(sens_bucket)},
    {"SENS_PRESSURE_BOOM", can_id::sens_pressure_boom, 5, Node::plant, 3, CommandSet::none, sens_pressure_boom, count_of(sens_pressure_boom)},
    {"SENS_PRESSURE_ARM", can_id::sens_pressure_arm, 5, Node::plant, 3, CommandSet::none, sens_pressure_arm, count_of(sens_pressure_arm)},
    {"SENS_PRESSURE_BUCKET", can_id::sens_pressure_bucket, 5, Node::plant, 3, CommandSet::none, sens_pressure_bucket, count_of(sens_pressure_bucket)},
    {"FW_HEARTBEAT", can_id::fw_heartbeat, 2, Node::firmware, 100, CommandSet::none, fw_heartbeat, count_of(fw_heartbeat)},
    {"PLANT_HEARTBEAT", can_id::plant_heartbeat, 2, Node::plant, 100, CommandSet::none, plant_heartbeat, count_of(plant_heartbeat)},
}};

}  // namespace

const std::array<MessageSpec, kMessageCount>& protocol_messages() { return kMessages; }

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
