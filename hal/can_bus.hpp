#pragma once
// The bus as the endpoints see it (ros2_control style: the ports never know which backend runs).
// Implementations neither allocate nor throw in send/receive/wait_readable.
#include <cstdint>

#include "hal/can_frame.hpp"

namespace exc::hal {

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Queues one frame for transmission; false when it could not be queued (full, bus down, bad frame).
  virtual bool send(const CanFrame& frame) = 0;
  // Takes the oldest received frame without blocking; false when none is waiting.
  virtual bool receive(CanFrame& frame) = 0;
  // Blocks until a frame can be received or timeout_ns elapses (0: just poll); true if one can.
  virtual bool wait_readable(std::int64_t timeout_ns) = 0;
};

}  // namespace exc::hal
