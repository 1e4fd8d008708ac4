#include "hal/can_ports.hpp"

#include "hal/can_bus_load.hpp"
#include "hal/clock.hpp"

namespace exc::hal {
namespace {

const MessageSpec& spec_of(std::uint32_t id) { return *find_message(id); }  // ids below are all in the table

constexpr std::uint64_t kSyncCycleMask = (1u << 20) - 1;  // SYNC's Cycle signal: 20 bits

// SENS_MACHINE's data signals, in the order of the DBC (and of can_protocol.cpp's table).
namespace sens {
constexpr int kPlantState = 0, kSwingAngle = 1, kSwingRate = 2, kPlantFaults = 3;
constexpr int kCylinderLength = 4;  // boom, arm, bucket: length at 4 + 2 c, rate at 5 + 2 c
constexpr int kPressureValid = 10;
constexpr int kPressures = 11;      // A, B of swing, boom, arm, bucket at 11 + 2 axis (+1)
constexpr int kPumps = 19;
constexpr int kSpools = 21;         // swing, boom, arm, bucket
constexpr int kCount = 25;
static_assert(kCount <= static_cast<int>(kMaxDataSignals));
}  // namespace sens

std::uint8_t nibble(std::uint64_t cycle) { return static_cast<std::uint8_t>(cycle & 0x0F); }

}  // namespace

std::size_t receive_ids(Node receiver, std::uint32_t* out, std::size_t capacity) {
  std::size_t n = 0;
  for (const MessageSpec& m : protocol_messages()) {
    // SUPERVISOR's one receiver is the firmware (the DBC): the plant's kernel filter keeps it out.
    const bool for_receiver = m.sender != receiver && (m.sender != Node::operator_station || receiver == Node::firmware);
    if (for_receiver && n < capacity) out[n++] = m.id;
  }
  return n;
}

// ---------------------------------------------------------------------------------------------------
// Both ends

CanPortEnd::CanPortEnd(CanBus& bus, CanFrameCodec::Config config, std::uint32_t heartbeat_id,
                       std::uint32_t emergency_id)
    : bus_(bus), codec_(config), heartbeat_(spec_of(heartbeat_id)), emergency_(spec_of(emergency_id)) {}

bool CanPortEnd::transmit(const MessageSpec& message, std::uint8_t counter, const double* values) {
  CanFrame frame;
  const EncodeReport report = encode_message(message, counter, values, frame);
  tx_.saturated += report.saturated;
  tx_.non_finite += report.non_finite;
  frame.wire_ns = frame_time_ns(frame);  // timed once: the receivers take it from the frame
  if (!bus_.send(frame)) {
    ++tx_.send_failed;
    return false;
  }
  ++tx_.frames_sent;
  tx_.bus_ns += static_cast<std::uint64_t>(frame.wire_ns);
  return true;
}

bool CanPortEnd::receive_valid(CanFrame& frame, const MessageSpec*& message) {
  while (bus_.receive(frame)) {
    rx_bus_ns_ += static_cast<std::uint64_t>(frame.wire_ns != 0 ? frame.wire_ns : frame_time_ns(frame));
    if (codec_.accept(frame, message) != RxVerdict::ok) continue;
    last_valid_rx_ns_ = frame.timestamp_ns != 0 ? frame.timestamp_ns : monotonic_now_ns();
    return true;
  }
  return false;
}

bool CanPortEnd::send_heartbeat(std::uint8_t state) {
  const double values[] = {static_cast<double>(state & 0x0F)};
  return transmit(heartbeat_, heartbeat_counter_++, values);
}

bool CanPortEnd::send_fault(bool emergency_stop, std::uint16_t fault_code) {
  const double values[] = {emergency_stop ? 1.0 : 0.0, static_cast<double>(fault_code)};
  return transmit(emergency_, emergency_counter_++, values);
}

// ---------------------------------------------------------------------------------------------------
// Firmware side

FirmwareCanPort::FirmwareCanPort(CanBus& bus, CanFrameCodec::Config config)
    : CanPortEnd(bus, config, can_id::fw_heartbeat, can_id::fw_emergency) {}

bool FirmwareCanPort::send_sync(std::uint64_t cycle) {
  cycle_ = cycle;
  have_sensors_ = false;
  const double values[] = {static_cast<double>(cycle & kSyncCycleMask)};
  return transmit(spec_of(can_id::sync), nibble(cycle), values);
}

bool FirmwareCanPort::write(const CommandState& command) {
  const std::uint8_t counter = nibble(command.cycle);
  switch (command.mode) {
    case CommandMode::valve:
      return transmit(spec_of(can_id::cmd_valve), counter, command.value.data());
    case CommandMode::pilot: {
      double pilots[2 * kAxisCount];  // A and B end per axis, the DBC's order
      for (int axis = 0; axis < kAxisCount; ++axis) {
        pilots[2 * axis] = command.pilot_a[axis];
        pilots[2 * axis + 1] = command.pilot_b[axis];
      }
      return transmit(spec_of(can_id::cmd_pilot), counter, pilots);
    }
    case CommandMode::effort:
      break;
  }
  return transmit(spec_of(can_id::cmd_effort), counter, command.value.data());
}

void FirmwareCanPort::apply(const MessageSpec& message, const CanFrame& frame, SensorState& state) {
  double v[kMaxDataSignals];  // any valid frame, also one this end never expects
  decode_message(message, frame, v);
  switch (message.id) {
    case can_id::sens_machine:
      state.plant_state = static_cast<std::uint8_t>(v[sens::kPlantState]);
      state.plant_faults = static_cast<std::uint8_t>(v[sens::kPlantFaults]);
      state.position[kSwing] = v[sens::kSwingAngle];
      state.velocity[kSwing] = v[sens::kSwingRate];
      for (int axis = kBoom; axis <= kBucket; ++axis) {
        state.position[axis] = v[sens::kCylinderLength + 2 * (axis - kBoom)];
        state.velocity[axis] = v[sens::kCylinderLength + 2 * (axis - kBoom) + 1];
      }
      state.pressure_valid = v[sens::kPressureValid] != 0.0;
      for (int axis = 0; axis < kAxisCount; ++axis) {
        state.pressure_a[axis] = v[sens::kPressures + 2 * axis];
        state.pressure_b[axis] = v[sens::kPressures + 2 * axis + 1];
      }
      for (int pump = 0; pump < kPumpCount; ++pump) state.pump_pressure[pump] = v[sens::kPumps + pump];
      for (int axis = 0; axis < kAxisCount; ++axis) state.spool[axis] = v[sens::kSpools + axis];
      if (frame_counter(frame) == nibble(cycle_)) have_sensors_ = true;
      break;
    case can_id::plant_heartbeat:
      // Kept apart from SENS_MACHINE's PlantState: a late heartbeat must not overwrite fresher state.
      state.plant_heartbeat_state = static_cast<std::uint8_t>(v[0]);
      break;
    case can_id::plant_emergency:
      state.plant_emergency = v[0] != 0.0;
      state.plant_fault_code = static_cast<std::uint16_t>(v[1]);
      break;
    case can_id::supervisor: {
      // Kept until the node takes it; a value outside the DBC's range is no command. Command none is
      // the station's keep-alive: heard, it tells the firmware a monitored link is there.
      const auto command = static_cast<unsigned>(v[0]);
      if (command <= 3) state.supervisor_pending |= static_cast<std::uint8_t>(1u << command);
      break;
    }
    default:
      break;
  }
}

bool FirmwareCanPort::read(SensorState& state) {
  CanFrame frame;
  const MessageSpec* message = nullptr;
  while (receive_valid(frame, message)) apply(*message, frame, state);
  if (have_sensors_) state.cycle = cycle_;
  state.motion_valid = have_sensors_;
  return have_sensors_;
}

// ---------------------------------------------------------------------------------------------------
// Operator station

OperatorCanPort::OperatorCanPort(CanBus& bus, std::uint8_t first_counter)
    : bus_(bus), spec_(spec_of(can_id::supervisor)), counter_(first_counter) {}

bool OperatorCanPort::send(SupervisorCommand command) {
  const double values[] = {static_cast<double>(command)};
  CanFrame frame;
  encode_message(spec_, counter_, values, frame);
  if (!bus_.send(frame)) return false;
  counter_ = static_cast<std::uint8_t>((counter_ + 1) & 0x0F);
  return true;
}

// ---------------------------------------------------------------------------------------------------
// Plant side

PlantCanPort::PlantCanPort(CanBus& bus, CanFrameCodec::Config config)
    : CanPortEnd(bus, config, can_id::plant_heartbeat, can_id::plant_emergency) {}

std::uint64_t PlantCanPort::cycle_of_counter(std::uint8_t counter) const {
  // Commands of cycle k arrive around SYNC(k) (after it, or after a lost SYNC(k) while the plant is
  // still at k - 1): take the cycle nearest the last SYNC with this counter, within -8..+7.
  if (!have_sync_) return counter;
  int diff = (counter - static_cast<int>(sync_cycle_ & 0x0F)) & 0x0F;
  if (diff >= 8) diff -= 16;
  return static_cast<std::uint64_t>(static_cast<std::int64_t>(sync_cycle_) + diff);
}

bool PlantCanPort::apply(const MessageSpec& message, const CanFrame& frame) {
  double v[kMaxDataSignals];  // any valid frame, also one this end never expects
  decode_message(message, frame, v);
  switch (message.id) {
    case can_id::sync: {
      const auto raw = static_cast<std::int64_t>(v[0]);
      if (!have_sync_) {
        sync_cycle_ = static_cast<std::uint64_t>(raw);
        have_sync_ = true;
      } else {
        // Extend the 20-bit cycle to the value nearest the expected next cycle.
        const std::uint64_t expected = sync_cycle_ + 1;
        constexpr std::int64_t kSpan = static_cast<std::int64_t>(kSyncCycleMask) + 1;
        std::int64_t diff = (raw - static_cast<std::int64_t>(expected & kSyncCycleMask)) & (kSpan - 1);
        if (diff >= kSpan / 2) diff -= kSpan;
        sync_cycle_ = static_cast<std::uint64_t>(static_cast<std::int64_t>(expected) + diff);
      }
      return true;
    }
    case can_id::cmd_effort:
    case can_id::cmd_valve:
      latest_.mode = message.id == can_id::cmd_effort ? CommandMode::effort : CommandMode::valve;
      for (int axis = 0; axis < kAxisCount; ++axis) latest_.value[axis] = v[axis];
      break;
    case can_id::cmd_pilot:
      latest_.mode = CommandMode::pilot;
      for (int axis = 0; axis < kAxisCount; ++axis) {
        latest_.pilot_a[axis] = v[2 * axis];
        latest_.pilot_b[axis] = v[2 * axis + 1];
      }
      break;
    case can_id::fw_heartbeat:
      latest_.firmware_mode = static_cast<std::uint8_t>(v[0]);
      return false;
    case can_id::fw_emergency:
      latest_.emergency_stop = v[0] != 0.0;
      latest_.fault_code = static_cast<std::uint16_t>(v[1]);
      return false;
    default:
      return false;
  }
  // A command frame: one frame is the whole set of its cycle.
  latest_.cycle = cycle_of_counter(frame_counter(frame));
  latest_.valid = true;
  fresh_ = true;
  return false;
}

bool PlantCanPort::poll_sync(std::uint64_t& cycle) {
  CanFrame frame;
  const MessageSpec* message = nullptr;
  while (receive_valid(frame, message)) {
    if (apply(*message, frame)) {
      cycle = sync_cycle_;
      return true;
    }
  }
  return false;
}

bool PlantCanPort::wait_sync(std::uint64_t& cycle, std::int64_t timeout_ns) {
  const std::int64_t deadline = monotonic_now_ns() + timeout_ns;
  for (;;) {
    if (poll_sync(cycle)) return true;
    const std::int64_t remaining = deadline - monotonic_now_ns();
    if (remaining <= 0) return false;
    bus().wait_readable(remaining);
  }
}

bool PlantCanPort::read(CommandState& command) {
  command = latest_;
  const bool fresh = fresh_;
  fresh_ = false;
  return fresh;
}

bool PlantCanPort::write(const SensorState& sensor) {
  double v[sens::kCount];
  v[sens::kPlantState] = static_cast<double>(sensor.plant_state & 0x0F);
  v[sens::kSwingAngle] = sensor.position[kSwing];
  v[sens::kSwingRate] = sensor.velocity[kSwing];
  v[sens::kPlantFaults] = static_cast<double>(sensor.plant_faults);
  for (int axis = kBoom; axis <= kBucket; ++axis) {
    v[sens::kCylinderLength + 2 * (axis - kBoom)] = sensor.position[axis];
    v[sens::kCylinderLength + 2 * (axis - kBoom) + 1] = sensor.velocity[axis];
  }
  v[sens::kPressureValid] = sensor.pressure_valid ? 1.0 : 0.0;
  for (int axis = 0; axis < kAxisCount; ++axis) {
    v[sens::kPressures + 2 * axis] = sensor.pressure_a[axis];
    v[sens::kPressures + 2 * axis + 1] = sensor.pressure_b[axis];
  }
  for (int pump = 0; pump < kPumpCount; ++pump) v[sens::kPumps + pump] = sensor.pump_pressure[pump];
  for (int axis = 0; axis < kAxisCount; ++axis) v[sens::kSpools + axis] = sensor.spool[axis];
  return transmit(spec_of(can_id::sens_machine), nibble(sensor.cycle), v);
}

}  // namespace exc::hal
