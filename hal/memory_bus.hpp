#pragma once
// An in-memory CAN bus with the broadcast semantics of a real one: a frame sent by one node reaches
// every other node attached to the same hub, in send order, never the sender itself. Each node has a
// fixed-capacity receive ring allocated when it attaches; a frame arriving at a full ring is dropped
// and counted (a real controller's mailbox overflow). Nothing allocates after attach().
//
// Threading: single-threaded (the in-process run alternates firmware and plant in one thread).
// Use SocketCAN (vcan) for two processes or threads.
#include <cstddef>
#include <cstdint>
#include <memory>

#include "hal/can_bus.hpp"

namespace exc::hal {

class MemoryBusHub;

class MemoryBusNode final : public CanBus {
 public:
  bool send(const CanFrame& frame) override;
  bool receive(CanFrame& frame) override;
  bool wait_readable(std::int64_t timeout_ns) override;  // never blocks: nothing else can deliver meanwhile

  std::size_t pending() const { return count_; }
  std::uint64_t overflows() const { return overflows_; }
  std::uint64_t sent() const { return sent_; }
  std::uint64_t received() const { return received_; }

 private:
  friend class MemoryBusHub;
  MemoryBusNode(MemoryBusHub& hub, std::size_t capacity);
  void deliver(const CanFrame& frame);

  MemoryBusHub& hub_;
  std::unique_ptr<CanFrame[]> ring_;
  std::size_t capacity_;
  std::size_t head_ = 0;  // oldest frame
  std::size_t count_ = 0;
  std::uint64_t overflows_ = 0;
  std::uint64_t sent_ = 0;
  std::uint64_t received_ = 0;
};

class MemoryBusHub {
 public:
  static constexpr std::size_t kMaxNodes = 8;
  // Frames get their timestamp from `clock_ns` at send (monotonic_now_ns when null), so runs can use
  // simulated time for determinism.
  using ClockFunction = std::int64_t (*)(void* context);
  MemoryBusHub();
  MemoryBusHub(ClockFunction clock_ns, void* clock_context);
  MemoryBusHub(const MemoryBusHub&) = delete;
  MemoryBusHub& operator=(const MemoryBusHub&) = delete;

  // Attaches a node with a receive ring of `capacity` frames; nullptr when kMaxNodes are attached.
  // The hub owns the node; it lives as long as the hub.
  MemoryBusNode* attach(std::size_t capacity = 256);
  std::size_t node_count() const { return node_count_; }
  std::uint64_t frames_sent() const { return frames_sent_; }

 private:
  friend class MemoryBusNode;
  void broadcast(const MemoryBusNode& sender, const CanFrame& frame);

  ClockFunction clock_ns_;
  void* clock_context_;
  std::unique_ptr<MemoryBusNode> nodes_[kMaxNodes];
  std::size_t node_count_ = 0;
  std::uint64_t frames_sent_ = 0;
};

}  // namespace exc::hal
