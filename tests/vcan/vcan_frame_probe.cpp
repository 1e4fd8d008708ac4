// vcan-frame-probe: sends the CAN and CAN FD frames given on the command line (cansend syntax) from
// one raw SocketCAN socket and prints, one per line in the same syntax, what a second socket on the
// same interface receives. The vcan tests run it inside vcan-vm and compare its output with what they
// asked it to send. Plain SocketCAN on purpose: it checks the VM's vcan0, not the project's HAL.
#include <linux/can.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

namespace {

constexpr const char* kUsage =
    "Usage: vcan-frame-probe [--timeout-ms MS] INTERFACE FRAME...\n"
    "Sends each FRAME (cansend syntax: 3 hex digits for an 11-bit ID or 8 for a 29-bit ID, '#',\n"
    "then 0..8 data bytes in hex, e.g. 123#DEADBEEF; CAN FD: '##', one hex digit of flags (1: bit-rate\n"
    "switch), then 0..64 bytes of a valid FD length, e.g. 180##1AABBCC) on INTERFACE from one raw CAN\n"
    "socket and prints what a second raw socket on INTERFACE receives, one frame per line, same\n"
    "syntax (CAN FD needs an interface with MTU 72; the kernel's CANFD_FDF marker is not shown).\n"
    "Exit status: 0 when every frame came back, 1 on a socket error or when a frame did not\n"
    "arrive within --timeout-ms (default 60000: a failure detector, not a speed requirement),\n"
    "2 for bad arguments.\n";

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

bool valid_fd_length(std::size_t n) {
  return n <= 8 || n == 12 || n == 16 || n == 20 || n == 24 || n == 32 || n == 48 || n == 64;
}

// Parses "ID#DATA" or "ID##FLAGS DATA"; on failure says which part of the argument is wrong.
bool parse_frame(const std::string& text, canfd_frame& frame, bool& fd, std::string& error) {
  std::memset(&frame, 0, sizeof frame);
  const std::size_t hash = text.find('#');
  if (hash != 3 && hash != 8) {
    error = "the ID must be 3 (11-bit) or 8 (29-bit) hex digits before '#'";
    return false;
  }
  std::uint32_t id = 0;
  for (std::size_t i = 0; i < hash; ++i) {
    const int d = hex_digit(text[i]);
    if (d < 0) {
      error = "the ID has a non-hex character at column " + std::to_string(i + 1);
      return false;
    }
    id = id * 16 + static_cast<std::uint32_t>(d);
  }
  if (hash == 3 ? id > CAN_SFF_MASK : id > CAN_EFF_MASK) {
    error = hash == 3 ? "an 11-bit ID must be in 000..7FF" : "a 29-bit ID must be in 00000000..1FFFFFFF";
    return false;
  }
  frame.can_id = hash == 8 ? (id | CAN_EFF_FLAG) : id;
  std::size_t data_at = hash + 1;
  fd = data_at < text.size() && text[data_at] == '#';
  if (fd) {
    const int flags = data_at + 1 < text.size() ? hex_digit(text[data_at + 1]) : -1;
    if (flags < 0) {
      error = "after '##' one hex digit of CAN FD flags must follow";
      return false;
    }
    frame.flags = static_cast<std::uint8_t>(flags);
    data_at += 2;
  }
  const std::string data = text.substr(data_at);
  const std::size_t max_bytes = fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  if (data.size() % 2 != 0 || data.size() > 2 * max_bytes || (fd && !valid_fd_length(data.size() / 2))) {
    error = fd ? "CAN FD data must be 0..8, 12, 16, 20, 24, 32, 48 or 64 bytes of two hex digits each"
               : "the data must be 0..8 bytes of two hex digits each";
    return false;
  }
  for (std::size_t i = 0; i < data.size(); i += 2) {
    const int hi = hex_digit(data[i]), lo = hex_digit(data[i + 1]);
    if (hi < 0 || lo < 0) {
      error = "the data has a non-hex character at column " + std::to_string(data_at + 1 + i);
      return false;
    }
    frame.data[i / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  frame.len = static_cast<std::uint8_t>(data.size() / 2);
  return true;
}

std::string format_frame(const canfd_frame& frame, bool fd) {
  char buf[160];
  int n = (frame.can_id & CAN_EFF_FLAG) ? std::snprintf(buf, sizeof buf, "%08X#", frame.can_id & CAN_EFF_MASK)
                                        : std::snprintf(buf, sizeof buf, "%03X#", frame.can_id & CAN_SFF_MASK);
  // BRS and ESI; not CANFD_FDF, which the kernel (6.0 on) sets in every FD frame it delivers.
  if (fd) n += std::snprintf(buf + n, sizeof buf - n, "#%X", frame.flags & (CANFD_BRS | CANFD_ESI));
  const int max_len = fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN;
  for (int i = 0; i < frame.len && i < max_len; ++i) n += std::snprintf(buf + n, sizeof buf - n, "%02X", frame.data[i]);
  return buf;
}

int open_raw(const char* interface_name) {
  const int fd = socket(PF_CAN, SOCK_RAW, CAN_RAW);
  if (fd < 0) {
    std::fprintf(stderr, "vcan-frame-probe: socket(PF_CAN): %s\n", std::strerror(errno));
    return -1;
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, interface_name, IFNAMSIZ - 1);
  if (ioctl(fd, SIOCGIFINDEX, &ifr) < 0) {
    std::fprintf(stderr, "vcan-frame-probe: interface %s: %s\n", interface_name, std::strerror(errno));
    close(fd);
    return -1;
  }
  const int on = 1;
  if (setsockopt(fd, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof on) < 0) {
    std::fprintf(stderr, "vcan-frame-probe: CAN_RAW_FD_FRAMES: %s\n", std::strerror(errno));
    close(fd);
    return -1;
  }
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifr.ifr_ifindex;
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) < 0) {
    std::fprintf(stderr, "vcan-frame-probe: bind %s: %s\n", interface_name, std::strerror(errno));
    close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

int main(int argc, char** argv) {
  int timeout_ms = 60000;
  int arg = 1;
  if (argc > 1 && (std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0)) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (argc > 2 && std::strcmp(argv[1], "--timeout-ms") == 0) {
    char* end = nullptr;
    const long v = std::strtol(argv[2], &end, 10);
    if (*argv[2] == '\0' || *end != '\0' || v < 1 || v > 3600000) {
      std::fprintf(stderr, "vcan-frame-probe: --timeout-ms '%s': must be an integer in 1..3600000\n", argv[2]);
      return 2;
    }
    timeout_ms = static_cast<int>(v);
    arg = 3;
  }
  if (argc - arg < 2) {
    std::fputs(kUsage, stderr);
    return 2;
  }
  const char* interface_name = argv[arg++];
  std::vector<canfd_frame> frames;
  std::vector<bool> is_fd;
  for (; arg < argc; ++arg) {
    canfd_frame f;
    bool fd = false;
    std::string error;
    if (!parse_frame(argv[arg], f, fd, error)) {
      std::fprintf(stderr, "vcan-frame-probe: frame '%s': %s\n", argv[arg], error.c_str());
      return 2;
    }
    frames.push_back(f);
    is_fd.push_back(fd);
  }

  // The receiver is bound before anything is sent, so no frame can pass unseen.
  const int rx = open_raw(interface_name);
  if (rx < 0) return 1;
  const int tx = open_raw(interface_name);
  if (tx < 0) return 1;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const canfd_frame& f = frames[k];
    // A classical frame goes out as a can_frame (CAN_MTU bytes), an FD frame as a canfd_frame.
    const std::size_t size = is_fd[k] ? CANFD_MTU : CAN_MTU;
    if (write(tx, &f, size) != static_cast<ssize_t>(size)) {
      std::fprintf(stderr, "vcan-frame-probe: send %s: %s\n", format_frame(f, is_fd[k]).c_str(), std::strerror(errno));
      return 1;
    }
    pollfd p{rx, POLLIN, 0};
    const int ready = poll(&p, 1, timeout_ms);
    if (ready <= 0) {
      std::fprintf(stderr, "vcan-frame-probe: %s did not come back within %d ms\n", format_frame(f, is_fd[k]).c_str(),
                   timeout_ms);
      return 1;
    }
    canfd_frame got{};
    const ssize_t n = read(rx, &got, sizeof got);
    if (n != static_cast<ssize_t>(CAN_MTU) && n != static_cast<ssize_t>(CANFD_MTU)) {
      std::fprintf(stderr, "vcan-frame-probe: receive: %s\n", n < 0 ? std::strerror(errno) : "neither CAN_MTU nor CANFD_MTU bytes");
      return 1;
    }
    std::printf("%s\n", format_frame(got, n == static_cast<ssize_t>(CANFD_MTU)).c_str());
  }
  close(tx);
  close(rx);
  return 0;
}
