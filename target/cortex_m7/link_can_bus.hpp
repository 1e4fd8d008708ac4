#pragma once
// The firmware's CAN bus on the emulated target: the CAN controller's mailboxes as two fixed queues in
// RAM. The firmware's port sends into the outbound one and reads the inbound one; the image's loop
// moves them over the link to the host at the cycle's edges (firmware_image.cpp), so the firmware's
// timed stages encode and decode frames as on a machine and never wait for the transport. No heap.
#include <cstddef>

#include "hal/can_bus.hpp"

namespace exc::target {

class LinkCanBus final : public hal::CanBus {
 public:
  // More than a cycle's frames each way (the plant's answer is three to four, the firmware's two to five).
  static constexpr std::size_t kFrames = 32;

  bool send(const hal::CanFrame& frame) override {
    if (!hal::sendable(frame) || out_count_ == kFrames) return false;
    out_[out_count_++] = frame;
    return true;
  }
  bool receive(hal::CanFrame& frame) override {
    if (in_next_ == in_count_) return false;
    frame = in_[in_next_++];
    return true;
  }
  bool wait_readable(std::int64_t) override { return in_next_ < in_count_; }

  // The loop's side: a frame from the host into the inbound mailboxes (false when they are full), and
  // the frames the firmware sent since the last take.
  bool deliver(const hal::CanFrame& frame) {
    if (in_next_ == in_count_) in_next_ = in_count_ = 0;
    if (in_count_ == kFrames) return false;
    in_[in_count_++] = frame;
    return true;
  }
  const hal::CanFrame* sent() const { return out_; }
  std::size_t sent_count() const { return out_count_; }
  void clear_sent() { out_count_ = 0; }

 private:
  hal::CanFrame in_[kFrames], out_[kFrames];
  std::size_t in_count_ = 0, in_next_ = 0, out_count_ = 0;
};

}  // namespace exc::target
