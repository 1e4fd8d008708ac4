#include "hal/memory_bus.hpp"

#include "hal/clock.hpp"

namespace exc::hal {

MemoryBusNode::MemoryBusNode(MemoryBusHub& hub, std::size_t capacity)
    : hub_(hub), ring_(new CanFrame[capacity > 0 ? capacity : 1]), capacity_(capacity > 0 ? capacity : 1) {}

bool MemoryBusNode::send(const CanFrame& frame) {
  if (!sendable(frame)) return false;  // not an 11-bit frame of a valid length
  ++sent_;
  hub_.broadcast(*this, frame);
  return true;
}

bool MemoryBusNode::receive(CanFrame& frame) {
  if (count_ == 0) return false;
  frame = ring_[head_];
  head_ = (head_ + 1) % capacity_;
  --count_;
  ++received_;
  return true;
}

bool MemoryBusNode::wait_readable(std::int64_t /*timeout_ns*/) { return count_ > 0; }

void MemoryBusNode::deliver(const CanFrame& frame) {
  if (count_ == capacity_) {
    ++overflows_;
    return;
  }
  ring_[(head_ + count_) % capacity_] = frame;
  ++count_;
}

namespace {
std::int64_t monotonic_clock(void*) { return monotonic_now_ns(); }
}  // namespace

MemoryBusHub::MemoryBusHub() : MemoryBusHub(&monotonic_clock, nullptr) {}
MemoryBusHub::MemoryBusHub(ClockFunction clock_ns, void* clock_context)
    : clock_ns_(clock_ns != nullptr ? clock_ns : &monotonic_clock), clock_context_(clock_context) {}

MemoryBusNode* MemoryBusHub::attach(std::size_t capacity) {
  if (node_count_ == kMaxNodes) return nullptr;
  nodes_[node_count_].reset(new MemoryBusNode(*this, capacity));
  return nodes_[node_count_++].get();
}

void MemoryBusHub::broadcast(const MemoryBusNode& sender, const CanFrame& frame) {
  CanFrame stamped = frame;
  stamped.timestamp_ns = clock_ns_(clock_context_);
  ++frames_sent_;
  for (std::size_t i = 0; i < node_count_; ++i) {
    if (nodes_[i].get() != &sender) nodes_[i]->deliver(stamped);
  }
}

}  // namespace exc::hal
