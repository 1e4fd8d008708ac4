#include "hal/socketcan_bus.hpp"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <vector>

#include "hal/clock.hpp"

namespace exc::hal {
namespace {

std::string describe(const std::string& interface_name, const char* call, int err) {
  return "SocketCAN interface '" + interface_name + "': " + call + " failed: " + std::strerror(err) +
         " (errno " + std::to_string(err) + ")";
}

std::int64_t to_ns(const timespec& ts) { return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec; }

// Sentinel ID for frames this protocol never uses (extended, remote, error): the codec counts them
// as unknown instead of mistaking their low bits for a standard ID.
constexpr std::uint32_t kNotStandardId = 0xFFFFFFFFu;

}  // namespace

bool SocketCanBus::kernel_supports_can(std::string* why) {
  const int fd = ::socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) {
    if (why != nullptr) *why = std::string("socket(PF_CAN, SOCK_RAW, CAN_RAW) failed: ") + std::strerror(errno);
    return false;
  }
  ::close(fd);
  return true;
}

std::unique_ptr<SocketCanBus> SocketCanBus::open(const std::string& interface_name, const std::uint32_t* ids,
                                                 std::size_t id_count, std::string& error) {
  if (interface_name.empty() || interface_name.size() >= IFNAMSIZ) {
    error = "SocketCAN interface '" + interface_name + "': name must be 1.." + std::to_string(IFNAMSIZ - 1) +
            " characters";
    return nullptr;
  }
  const int fd = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (fd < 0) {
    error = describe(interface_name, "socket(PF_CAN, SOCK_RAW, CAN_RAW)", errno);
    return nullptr;
  }
  auto fail = [&](const char* call) {
    error = describe(interface_name, call, errno);
    ::close(fd);
    return nullptr;
  };

  const unsigned index = ::if_nametoindex(interface_name.c_str());
  if (index == 0) return fail("if_nametoindex");

  // Kernel filters: exact 11-bit match, data frames only (the mask includes the EFF and RTR flags).
  if (id_count > 0) {
    std::vector<can_filter> filters(id_count);
    for (std::size_t i = 0; i < id_count; ++i) {
      filters[i].can_id = ids[i] & CAN_SFF_MASK;
      filters[i].can_mask = CAN_SFF_MASK | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FILTER, filters.data(),
                     static_cast<socklen_t>(filters.size() * sizeof(can_filter))) < 0) {
      return fail("setsockopt(CAN_RAW_FILTER)");
    }
  }
  const int on = 1;
  if (::setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof(on)) < 0) return fail("setsockopt(CAN_RAW_FD_FRAMES)");
  if (::setsockopt(fd, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof(on)) < 0) return fail("setsockopt(SO_TIMESTAMPNS)");
  // Every frame of the protocol is CAN FD: an interface with the classical MTU would refuse them all.
  ifreq request{};
  std::memcpy(request.ifr_name, interface_name.c_str(), interface_name.size() + 1);
  if (::ioctl(fd, SIOCGIFMTU, &request) < 0) return fail("ioctl(SIOCGIFMTU)");
  if (request.ifr_mtu != static_cast<int>(CANFD_MTU)) {
    error = "SocketCAN interface '" + interface_name + "': MTU " + std::to_string(request.ifr_mtu) +
            " does not carry CAN FD frames (" + std::to_string(CANFD_MTU) + "): `ip link set " + interface_name +
            " mtu " + std::to_string(CANFD_MTU) + "` (and bitrate/dbitrate on a real controller)";
    ::close(fd);
    return nullptr;
  }

  sockaddr_can address{};
  address.can_family = AF_CAN;
  address.can_ifindex = static_cast<int>(index);
  if (::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) < 0) return fail("bind");

  return std::unique_ptr<SocketCanBus>(new SocketCanBus(fd, interface_name));
}

SocketCanBus::SocketCanBus(int fd, std::string interface_name)
    : fd_(fd), interface_name_(std::move(interface_name)), control_{}, raw_{} {
  static_assert(sizeof(control_) >= CMSG_SPACE(sizeof(timespec)), "control buffer too small");
  static_assert(sizeof(raw_) == CANFD_MTU && CAN_MTU <= CANFD_MTU, "receive buffer must hold one canfd_frame");
}

SocketCanBus::~SocketCanBus() {
  if (fd_ >= 0) ::close(fd_);
}

bool SocketCanBus::send(const CanFrame& frame) {
  if (!sendable(frame)) {
    ++stats_.send_failed;
    return false;
  }
  ssize_t n = 0;
  std::size_t size = 0;
  if (frame.fd) {
    canfd_frame raw{};
    raw.can_id = frame.id;
    raw.len = frame.len;
    raw.flags = frame.brs ? CANFD_BRS : 0;
    std::memcpy(raw.data, frame.data, frame.len);
    size = CANFD_MTU;
    n = ::send(fd_, &raw, size, MSG_DONTWAIT);
  } else {
    can_frame raw{};
    raw.can_id = frame.id;
    raw.len = frame.len;
    std::memcpy(raw.data, frame.data, frame.len);
    size = CAN_MTU;
    n = ::send(fd_, &raw, size, MSG_DONTWAIT);
  }
  if (n != static_cast<ssize_t>(size)) {
    ++stats_.send_failed;
    stats_.last_errno = n < 0 ? errno : EIO;
    return false;
  }
  ++stats_.sent;
  return true;
}

bool SocketCanBus::receive(CanFrame& frame) {
  // canfd_frame and can_frame share the layout of id, length and data; CAN_MTU bytes: classical.
  iovec iov{raw_, sizeof(raw_)};
  msghdr message{};
  message.msg_iov = &iov;
  message.msg_iovlen = 1;
  message.msg_control = control_;
  message.msg_controllen = sizeof(control_);
  const ssize_t n = ::recvmsg(fd_, &message, MSG_DONTWAIT);
  if (n < 0) {
    if (errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR) {
      ++stats_.receive_errors;
      stats_.last_errno = errno;
    }
    return false;
  }
  if (n != static_cast<ssize_t>(CAN_MTU) && n != static_cast<ssize_t>(CANFD_MTU)) {
    ++stats_.receive_errors;
    return false;
  }
  canfd_frame raw;
  std::memcpy(&raw, raw_, sizeof(raw));
  ++stats_.received;
  if ((raw.can_id & (CAN_EFF_FLAG | CAN_RTR_FLAG | CAN_ERR_FLAG)) != 0) {
    ++stats_.not_standard;
    frame.id = kNotStandardId;
  } else {
    frame.id = raw.can_id & CAN_SFF_MASK;
  }
  frame.fd = n == static_cast<ssize_t>(CANFD_MTU);
  frame.brs = frame.fd && (raw.flags & CANFD_BRS) != 0;
  const std::uint8_t max_len = frame.fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  frame.len = raw.len <= max_len ? raw.len : max_len;
  std::memset(frame.data, 0, sizeof(frame.data));
  std::memcpy(frame.data, raw.data, frame.len);

  // SO_TIMESTAMPNS stamps with CLOCK_REALTIME; shift it onto CLOCK_MONOTONIC with the current offset
  // between the two clocks (exact unless the wall clock is stepped between reception and now).
  frame.timestamp_ns = 0;
  for (cmsghdr* c = CMSG_FIRSTHDR(&message); c != nullptr; c = CMSG_NXTHDR(&message, c)) {
    if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SCM_TIMESTAMPNS) {
      timespec stamp{};
      std::memcpy(&stamp, CMSG_DATA(c), sizeof(stamp));
      timespec real_now{};
      clock_gettime(CLOCK_REALTIME, &real_now);
      frame.timestamp_ns = to_ns(stamp) - to_ns(real_now) + monotonic_now_ns();
    }
  }
  if (frame.timestamp_ns == 0) frame.timestamp_ns = monotonic_now_ns();
  return true;
}

bool SocketCanBus::wait_readable(std::int64_t timeout_ns) {
  pollfd p{fd_, POLLIN, 0};
  timespec timeout{};
  if (timeout_ns > 0) {
    timeout.tv_sec = static_cast<time_t>(timeout_ns / 1'000'000'000);
    timeout.tv_nsec = static_cast<long>(timeout_ns % 1'000'000'000);
  }
  const int r = ::ppoll(&p, 1, &timeout, nullptr);
  return r > 0 && (p.revents & POLLIN) != 0;
}

}  // namespace exc::hal
