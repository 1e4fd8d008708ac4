#pragma once
// The two ends of the protocol on top of any CanBus: FirmwareCanPort (the controller) and
// PlantCanPort (the machine). The cycle: the firmware sends SYNC(k); the plant advances one step and
// answers with its sensor frames of cycle k; the firmware reads them, computes and writes its
// commands of cycle k, which the plant applies at SYNC(k + 1). Cyclic frames carry k mod 16 as their
// counter, so each end can tell which cycle a frame belongs to. Only frames that pass validation
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
  std::uint64_t bits = 0;        // exact on-wire bits of the frames sent (stuffing included)
};

// The identifiers `receiver` listens to (for SocketCAN kernel filters). Returns the count written.
std::size_t receive_ids(Node receiver, std::uint32_t* out, std::size_t capacity);

class FirmwareCanPort {
 public:
  explicit FirmwareCanPort(CanBus& bus, CanFrameCodec::Config config = {});

  // Starts cycle `cycle`: sends SYNC and resets the completeness of read().
  bool send_sync(std::uint64_t cycle);
  // Drains the bus and folds every valid frame into `state`. True when the swing and the three
  // cylinder frames of the current cycle have all arrived; then state.cycle is that cycle and
  // state.motion_valid is set.
  bool read(SensorState& state);
  // CLOCK_MONOTONIC time of the last valid frame (0: none yet): the watchdog's input.
  std::int64_t last_valid_rx_ns() const { return last_valid_rx_ns_; }
  // Sends the command set of `command.mode` (counter: command.cycle mod 16).
  bool write(const CommandState& command);
  bool send_heartbeat(std::uint8_t firmware_mode);
  bool send_fault(bool emergency_stop, std::uint16_t fault_code);

  const RxStats& rx_stats() const { return codec_.stats(); }
  const TxStats& tx_stats() const { return tx_; }
  // Exact on-wire bits of every frame received, valid or not (with tx_stats().bits: the whole bus of
  // a two-node network, the figure bus load is computed from).
  std::uint64_t rx_bits() const { return rx_bits_; }

 private:
  bool transmit(const MessageSpec& message, std::uint8_t counter, const double* values);
  void apply(const MessageSpec& message, const CanFrame& frame, SensorState& state);

  CanBus& bus_;
  CanFrameCodec codec_;
  TxStats tx_;
  std::uint64_t cycle_ = 0;
  std::uint8_t motion_mask_ = 0;  // bit i: axis i's frame of cycle_ arrived
  std::int64_t last_valid_rx_ns_ = 0;
  std::uint64_t rx_bits_ = 0;
  std::uint8_t heartbeat_counter_ = 0;
  std::uint8_t emergency_counter_ = 0;
};

class PlantCanPort {
 public:
  explicit PlantCanPort(CanBus& bus, CanFrameCodec::Config config = {});

  // Reads frames in order up to and including the next valid SYNC (commands before it are latched).
  // True with `cycle` set when a SYNC was found: the plant then advances exactly one step.
  bool poll_sync(std::uint64_t& cycle);
  // poll_sync, blocking on the bus up to timeout_ns (on the single-threaded memory bus nothing can
  // arrive while waiting: use poll_sync there).
  bool wait_sync(std::uint64_t& cycle, std::int64_t timeout_ns);
  // The latest valid command set. True when a new complete set arrived since the previous call.
  bool read(CommandState& command);
  // Sends the sensor frames for sensor.cycle, and one cylinder's pressures (round robin) when that
  // cylinder's pressure_valid is set.
  bool write(const SensorState& sensor);
  bool send_heartbeat(std::uint8_t plant_state);
  bool send_fault(bool emergency_stop, std::uint16_t fault_code);

  std::int64_t last_valid_rx_ns() const { return last_valid_rx_ns_; }
  const RxStats& rx_stats() const { return codec_.stats(); }
  const TxStats& tx_stats() const { return tx_; }

 private:
  bool transmit(const MessageSpec& message, std::uint8_t counter, const double* values);
  // Returns true when the frame was a SYNC.
  bool apply(const MessageSpec& message, const CanFrame& frame);
  std::uint64_t cycle_of_counter(std::uint8_t counter) const;

  CanBus& bus_;
  CanFrameCodec codec_;
  TxStats tx_;
  bool have_sync_ = false;
  std::uint64_t sync_cycle_ = 0;
  CommandState latest_;
  bool fresh_ = false;
  int effort_a_counter_ = -1;  // counter of the last CMD_EFFORT_A / _B, to pair them
  int effort_b_counter_ = -2;
  std::array<double, kAxisCount> effort_{};
  std::int64_t last_valid_rx_ns_ = 0;
  std::uint8_t heartbeat_counter_ = 0;
  std::uint8_t emergency_counter_ = 0;
};

}  // namespace exc::hal
