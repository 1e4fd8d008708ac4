#include "hal/can_ports.hpp"

#include "hal/can_bus_load.hpp"
#include "hal/clock.hpp"

namespace exc::hal {
namespace {

const MessageSpec& spec_of(std::uint32_t id) { return *find_message(id); }  // ids below are all in the table

constexpr std::uint32_t kMotionIds[kAxisCount] = {can_id::sens_swing, can_id::sens_boom, can_id::sens_arm,
                                                  can_id::sens_bucket};
constexpr std::uint32_t kPressureIds[kCylinderCount] = {can_id::sens_pressure_boom, can_id::sens_pressure_arm,
                                                        can_id::sens_pressure_bucket};
constexpr std::uint8_t kAllAxes = (1u << kAxisCount) - 1;
constexpr std::uint64_t kSyncCycleMask = (1u << 20) - 1;  // SYNC's Cycle signal: 20 bits

std::uint8_t nibble(std::uint64_t cycle) { return static_cast<std::uint8_t>(cycle & 0x0F); }

// Both ends send the same way: encode (counting saturated and non-finite signals), send, count.
bool encode_and_send(CanBus& bus, TxStats& tx, const MessageSpec& message, std::uint8_t counter,
                     const double* values) {
  CanFrame frame;
  const EncodeReport report = encode_message(message, counter, values, frame);
  tx.saturated += report.saturated;
  tx.non_finite += report.non_finite;
  if (!bus.send(frame)) {
    ++tx.send_failed;
    return false;
  }
  ++tx.frames_sent;
  tx.bits += static_cast<std::uint64_t>(classical_frame_bits(frame.id, frame.dlc, frame.data));
  return true;
}

}  // namespace

std::size_t receive_ids(Node receiver, std::uint32_t* out, std::size_t capacity) {
  std::size_t n = 0;
  for (const MessageSpec& m : protocol_messages()) {
    if (m.sender != receiver && n < capacity) out[n++] = m.id;
  }
  return n;
}

// ---------------------------------------------------------------------------------------------------
// Firmware side

FirmwareCanPort::FirmwareCanPort(CanBus& bus, CanFrameCodec::Config config) : bus_(bus), codec_(config) {}

bool FirmwareCanPort::transmit(const MessageSpec& message, std::uint8_t counter, const double* values) {
  return encode_and_send(bus_, tx_, message, counter, values);
}

bool FirmwareCanPort::send_sync(std::uint64_t cycle) {
  cycle_ = cycle;
  motion_mask_ = 0;
  const double values[] = {static_cast<double>(cycle & kSyncCycleMask)};
  return transmit(spec_of(can_id::sync), nibble(cycle), values);
}

bool FirmwareCanPort::write(const CommandState& command) {
  const std::uint8_t counter = nibble(command.cycle);
  if (command.mode == CommandMode::valve) {
    return transmit(spec_of(can_id::cmd_valve), counter, command.value.data());
  }
  const double a[] = {command.value[kSwing], command.value[kBoom]};
  const double b[] = {command.value[kArm], command.value[kBucket]};
  const bool sent_a = transmit(spec_of(can_id::cmd_effort_a), counter, a);
  const bool sent_b = transmit(spec_of(can_id::cmd_effort_b), counter, b);
  return sent_a && sent_b;
}

bool FirmwareCanPort::send_heartbeat(std::uint8_t firmware_mode) {
  const double values[] = {static_cast<double>(firmware_mode & 0x0F)};
  return transmit(spec_of(can_id::fw_heartbeat), heartbeat_counter_++, values);
}

bool FirmwareCanPort::send_fault(bool emergency_stop, std::uint16_t fault_code) {
  const double values[] = {emergency_stop ? 1.0 : 0.0, static_cast<double>(fault_code)};
  return transmit(spec_of(can_id::fw_emergency), emergency_counter_++, values);
}

void FirmwareCanPort::apply(const MessageSpec& message, const CanFrame& frame, SensorState& state) {
  double v[6];
  decode_message(message, frame, v);
  for (int axis = 0; axis < kAxisCount; ++axis) {
    if (message.id != kMotionIds[axis]) continue;
    if (axis == kSwing) {
      state.plant_state = static_cast<std::uint8_t>(v[0]);
      state.position[kSwing] = v[1];
      state.velocity[kSwing] = v[2];
      state.plant_faults = static_cast<std::uint8_t>(v[3]);
    } else {
      state.position[axis] = v[0];
      state.velocity[axis] = v[1];
    }
    if (frame_counter(frame) == nibble(cycle_)) motion_mask_ |= static_cast<std::uint8_t>(1u << axis);
    return;
  }
  for (int c = 0; c < kCylinderCount; ++c) {
    if (message.id != kPressureIds[c]) continue;
    state.pressure_a[c] = v[0];
    state.pressure_b[c] = v[1];
    state.pressure_valid[c] = true;
    return;
  }
  if (message.id == can_id::plant_heartbeat) {
    // Kept apart from SENS_SWING's PlantState: a late heartbeat must not overwrite fresher state.
    state.plant_heartbeat_state = static_cast<std::uint8_t>(v[0]);
  } else if (message.id == can_id::plant_emergency) {
    state.plant_emergency = v[0] != 0.0;
    state.plant_fault_code = static_cast<std::uint16_t>(v[1]);
  }
}

bool FirmwareCanPort::read(SensorState& state) {
  CanFrame frame;
  while (bus_.receive(frame)) {
    rx_bits_ += static_cast<std::uint64_t>(classical_frame_bits(frame.id, frame.dlc, frame.data));
    const MessageSpec* message = nullptr;
    if (codec_.accept(frame, message) != RxVerdict::ok) continue;
    last_valid_rx_ns_ = frame.timestamp_ns != 0 ? frame.timestamp_ns : monotonic_now_ns();
    apply(*message, frame, state);
  }
  const bool complete = motion_mask_ == kAllAxes;
  if (complete) state.cycle = cycle_;
  state.motion_valid = complete;
  return complete;
}

// ---------------------------------------------------------------------------------------------------
// Plant side

PlantCanPort::PlantCanPort(CanBus& bus, CanFrameCodec::Config config) : bus_(bus), codec_(config) {}

bool PlantCanPort::transmit(const MessageSpec& message, std::uint8_t counter, const double* values) {
  return encode_and_send(bus_, tx_, message, counter, values);
}

std::uint64_t PlantCanPort::cycle_of_counter(std::uint8_t counter) const {
  // Commands of cycle k arrive around SYNC(k) (after it, or after a lost SYNC(k) while the plant is
  // still at k - 1): take the cycle nearest the last SYNC with this counter, within -8..+7.
  if (!have_sync_) return counter;
  int diff = (counter - static_cast<int>(sync_cycle_ & 0x0F)) & 0x0F;
  if (diff >= 8) diff -= 16;
  return static_cast<std::uint64_t>(static_cast<std::int64_t>(sync_cycle_) + diff);
}

bool PlantCanPort::apply(const MessageSpec& message, const CanFrame& frame) {
  double v[6];
  decode_message(message, frame, v);
  const std::uint8_t counter = frame_counter(frame);
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
    case can_id::cmd_effort_a:
      effort_[kSwing] = v[0];
      effort_[kBoom] = v[1];
      effort_a_counter_ = counter;
      break;
    case can_id::cmd_effort_b:
      effort_[kArm] = v[0];
      effort_[kBucket] = v[1];
      effort_b_counter_ = counter;
      break;
    case can_id::cmd_valve:
      latest_.mode = CommandMode::valve;
      for (int i = 0; i < kAxisCount; ++i) latest_.value[i] = v[i];
      latest_.cycle = cycle_of_counter(counter);
      latest_.valid = true;
      fresh_ = true;
      break;
    case can_id::fw_heartbeat:
      latest_.firmware_mode = static_cast<std::uint8_t>(v[0]);
      break;
    case can_id::fw_emergency:
      latest_.emergency_stop = v[0] != 0.0;
      latest_.fault_code = static_cast<std::uint16_t>(v[1]);
      break;
    default:
      break;
  }
  if ((message.id == can_id::cmd_effort_a || message.id == can_id::cmd_effort_b) &&
      effort_a_counter_ == effort_b_counter_) {
    // Both halves of the same cycle: only then is the effort set consistent.
    latest_.mode = CommandMode::effort;
    latest_.value = effort_;
    latest_.cycle = cycle_of_counter(counter);
    latest_.valid = true;
    fresh_ = true;
    effort_a_counter_ = -1;
    effort_b_counter_ = -2;
  }
  return false;
}

bool PlantCanPort::poll_sync(std::uint64_t& cycle) {
  CanFrame frame;
  while (bus_.receive(frame)) {
    const MessageSpec* message = nullptr;
    if (codec_.accept(frame, message) != RxVerdict::ok) continue;
    last_valid_rx_ns_ = frame.timestamp_ns != 0 ? frame.timestamp_ns : monotonic_now_ns();
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
    bus_.wait_readable(remaining);
  }
}

bool PlantCanPort::read(CommandState& command) {
  command = latest_;
  const bool fresh = fresh_;
  fresh_ = false;
  return fresh;
}

bool PlantCanPort::write(const SensorState& sensor) {
  const std::uint8_t counter = nibble(sensor.cycle);
  bool ok = true;
  const double swing[] = {static_cast<double>(sensor.plant_state & 0x0F), sensor.position[kSwing],
                          sensor.velocity[kSwing], static_cast<double>(sensor.plant_faults)};
  ok &= transmit(spec_of(can_id::sens_swing), counter, swing);
  for (int axis = kBoom; axis <= kBucket; ++axis) {
    const double cylinder[] = {sensor.position[axis], sensor.velocity[axis]};
    ok &= transmit(spec_of(kMotionIds[axis]), counter, cylinder);
  }
  const int c = static_cast<int>(sensor.cycle % kPressureRoundRobin);
  if (sensor.pressure_valid[c]) {
    // Pressure frames come every third cycle: their counter is the cycle divided by 3, so it still
    // advances by one per frame of that ID.
    const double pressures[] = {sensor.pressure_a[c], sensor.pressure_b[c]};
    ok &= transmit(spec_of(kPressureIds[c]), nibble(sensor.cycle / kPressureRoundRobin), pressures);
  }
  return ok;
}

bool PlantCanPort::send_heartbeat(std::uint8_t plant_state) {
  const double values[] = {static_cast<double>(plant_state & 0x0F)};
  return transmit(spec_of(can_id::plant_heartbeat), heartbeat_counter_++, values);
}

bool PlantCanPort::send_fault(bool emergency_stop, std::uint16_t fault_code) {
  const double values[] = {emergency_stop ? 1.0 : 0.0, static_cast<double>(fault_code)};
  return transmit(spec_of(can_id::plant_emergency), emergency_counter_++, values);
}

}  // namespace exc::hal
