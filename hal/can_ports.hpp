#pragma once
// The two ends of the protocol on top of any CanBus: FirmwareCanPort (the controller) and
// PlantCanPort (the machine). The cycle: the firmware sends SYNC(k); the plant advances one step and
// answers with SENS_MACHINE of cycle k; the firmware reads it, computes and writes its command frame
// of cycle k, which the plant applies at SYNC(k + 1). Cyclic frames carry k mod 16 as their counter,
// so each end can tell which cycle a frame belongs to. Only frames that pass validation
// (CanFrameCodec) change state or feed the watchdog time. No allocation, no exceptions.
#include <cstddef>
#include <cstdint>

#include "hal/can_bus.hpp"
#include "hal/can_codec.hpp"
#include "hal/excavator_interface.hpp"

namespace exc::hal {

struct TxStats {
  std::uint64_t frames_sent = 0;
  std::uint64_t send_failed = 0;
  std::uint64_t saturated = 0;   // signals clamped to their DBC range
  std::uint64_t non_finite = 0;  // NaN/inf values replaced before sending
  std::uint64_t bus_ns = 0;      // exact on-wire time of the frames sent (stuffing and both bit rates)
};

// The identifiers `receiver` listens to (for SocketCAN kernel filters). Returns the count written.
std::size_t receive_ids(Node receiver, std::uint32_t* out, std::size_t capacity);

// What both ends have alike: the bus, the validating codec, the send counters, the watchdog time and
// the two event frames each end sends (its heartbeat and its emergency frame, with their own counters).
class CanPortEnd {
 public:
  bool send_heartbeat(std::uint8_t state);
  bool send_fault(bool emergency_stop, std::uint16_t fault_code);

  // CLOCK_MONOTONIC time of the last valid frame (0: none yet): the watchdog's input.
  std::int64_t last_valid_rx_ns() const { return last_valid_rx_ns_; }
  const RxStats& rx_stats() const { return codec_.stats(); }
  const TxStats& tx_stats() const { return tx_; }
  // Exact on-wire time of every frame received, valid or not. With tx_stats().bus_ns: the whole bus of
  // a two-node network, the figure bus load is computed from.
  std::uint64_t rx_bus_ns() const { return rx_bus_ns_; }

 protected:
  CanPortEnd(CanBus& bus, CanFrameCodec::Config config, std::uint32_t heartbeat_id, std::uint32_t emergency_id);
  bool transmit(const MessageSpec& message, std::uint8_t counter, const double* values);
  // Takes frames off the bus until one passes validation (then true, with its spec); false when the
  // bus has no more.
  bool receive_valid(CanFrame& frame, const MessageSpec*& message);
  CanBus& bus() { return bus_; }

 private:
  CanBus& bus_;
  CanFrameCodec codec_;
  TxStats tx_;
  std::int64_t last_valid_rx_ns_ = 0;
  std::uint64_t rx_bus_ns_ = 0;
  const MessageSpec& heartbeat_;
  const MessageSpec& emergency_;
  std::uint8_t heartbeat_counter_ = 0;
  std::uint8_t emergency_counter_ = 0;
};

class FirmwareCanPort : public CanPortEnd {
 public:
  explicit FirmwareCanPort(CanBus& bus, CanFrameCodec::Config config = {});

  // Starts cycle `cycle`: sends SYNC and resets the completeness of read().
  bool send_sync(std::uint64_t cycle);
  // Drains the bus and folds every valid frame into `state`. True when SENS_MACHINE of the current
  // cycle has arrived; then state.cycle is that cycle and state.motion_valid is set.
  bool read(SensorState& state);
  // Sends the command frame of `command.mode` (counter: command.cycle mod 16).
  bool write(const CommandState& command);

 private:
  void apply(const MessageSpec& message, const CanFrame& frame, SensorState& state);

  std::uint64_t cycle_ = 0;
  bool have_sensors_ = false;  // SENS_MACHINE of cycle_ arrived
};

// An operator station (or remote e-stop kit) on the bus: sends SUPERVISOR frames, one per command,
// counting its own sends. A program that sends one command and exits starts a new sequence each
// run, which the firmware's codec accepts as a sender that paused (more than 5 ms since its last).
class OperatorCanPort {
 public:
  explicit OperatorCanPort(CanBus& bus, std::uint8_t first_counter = 0);
  bool send(SupervisorCommand command);
  std::uint8_t next_counter() const { return counter_; }

 private:
  CanBus& bus_;
  const MessageSpec& spec_;
  std::uint8_t counter_;
};

class PlantCanPort : public CanPortEnd {
 public:
  explicit PlantCanPort(CanBus& bus, CanFrameCodec::Config config = {});

  // Reads frames in order up to and including the next valid SYNC (commands before it are latched).
  // True with `cycle` set when a SYNC was found: the plant then advances exactly one step.
  bool poll_sync(std::uint64_t& cycle);
  // poll_sync, blocking on the bus up to timeout_ns (on the single-threaded memory bus nothing can
  // arrive while waiting: use poll_sync there).
  bool wait_sync(std::uint64_t& cycle, std::int64_t timeout_ns);
  // The latest valid command set (CMD_EFFORT, CMD_VALVE or CMD_PILOT). True when a new one arrived
  // since the previous call.
  bool read(CommandState& command);
  // Sends SENS_MACHINE for sensor.cycle.
  bool write(const SensorState& sensor);

 private:
  // Returns true when the frame was a SYNC.
  bool apply(const MessageSpec& message, const CanFrame& frame);
  std::uint64_t cycle_of_counter(std::uint8_t counter) const;

  bool have_sync_ = false;
  std::uint64_t sync_cycle_ = 0;
  CommandState latest_;
  bool fresh_ = false;
};

}  // namespace exc::hal
