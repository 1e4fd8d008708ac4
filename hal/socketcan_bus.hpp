#pragma once
// The Linux SocketCAN backend: a raw CAN socket (PF_CAN, SOCK_RAW, CAN_RAW) bound to one named
// interface (can0, vcan0, ...), non-blocking, with CAN FD frames enabled (CAN_RAW_FD_FRAMES: FD frames
// go out as canfd_frame, CANFD_MTU, with CANFD_BRS when the frame asks for the switch; both MTUs are
// received, a classical frame reaching the codec as fd = false), kernel receive filters for exactly
// the IDs this end listens to and kernel receive timestamps (SO_TIMESTAMPNS), converted to
// CLOCK_MONOTONIC. The interface must carry FD frames (MTU 72: `ip link set vcan0 mtu 72`); open()
// says so when it does not.
// Like a real bus (and MemoryBusNode), a node does not receive its own frames; other sockets on the
// same host do (the kernel's default CAN_RAW_LOOPBACK), which is how two processes share vcan0.
// send/receive/wait_readable neither allocate nor throw.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>

#include "hal/can_bus.hpp"

namespace exc::hal {

struct SocketCanStats {
  std::uint64_t sent = 0;
  std::uint64_t send_failed = 0;      // queue full (ENOBUFS/EAGAIN) or interface down
  std::uint64_t received = 0;
  std::uint64_t receive_errors = 0;   // recvmsg failures other than "nothing waiting"
  std::uint64_t not_standard = 0;     // extended, remote or error frames (passed on, ID marked invalid)
  int last_errno = 0;
};

class SocketCanBus final : public CanBus {
 public:
  // Opens `interface_name`. `ids`/`id_count`: the 11-bit identifiers to receive (kernel filter);
  // id_count == 0 receives everything. On failure returns nullptr and sets `error` to a message that
  // names the interface, the failing call and the errno text (or the MTU that cannot carry CAN FD).
  // Allocates: call before the loop.
  static std::unique_ptr<SocketCanBus> open(const std::string& interface_name, const std::uint32_t* ids,
                                            std::size_t id_count, std::string& error);
  ~SocketCanBus() override;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;

  bool send(const CanFrame& frame) override;
  bool receive(CanFrame& frame) override;
  bool wait_readable(std::int64_t timeout_ns) override;

  const SocketCanStats& stats() const { return stats_; }
  const std::string& interface_name() const { return interface_name_; }
  int native_handle() const { return fd_; }

  // Whether this kernel can create CAN sockets at all (false: no CAN support, e.g. a container).
  static bool kernel_supports_can(std::string* why = nullptr);

 private:
  SocketCanBus(int fd, std::string interface_name);
  int fd_;
  std::string interface_name_;
  SocketCanStats stats_;
  alignas(8) unsigned char control_[64];  // recvmsg control buffer, sized for one timespec cmsg
  alignas(8) unsigned char raw_[72];      // one canfd_frame (CANFD_MTU), or a can_frame (CAN_MTU)
};

}  // namespace exc::hal
