// vcan-frame-probe: sends the CAN frames given on the command line (cansend syntax) from one raw
// SocketCAN socket and prints, one per line in the same syntax, what a second socket on the same
// interface receives. The vcan tests run it inside vcan-vm and compare its output with what they
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
    "then 0..8 data bytes in hex, e.g. 123#DEADBEEF) on INTERFACE from one raw CAN socket and\n"
    "prints what a second raw socket on INTERFACE receives, one frame per line, same syntax.\n"
    "Exit status: 0 when every frame came back, 1 on a socket error or when a frame did not\n"
    "arrive within --timeout-ms (default 60000: a failure detector, not a speed requirement),\n"
    "2 for bad arguments.\n";

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

// Parses "ID#DATA"; on failure says which part of the argument is wrong.
bool parse_frame(const std::string& text, can_frame& frame, std::string& error) {
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
  const std::string data = text.substr(hash + 1);
  if (data.size() % 2 != 0 || data.size() > 16) {
    error = "the data must be 0..8 bytes of two hex digits each";
    return false;
  }
  for (std::size_t i = 0; i < data.size(); i += 2) {
    const int hi = hex_digit(data[i]), lo = hex_digit(data[i + 1]);
    if (hi < 0 || lo < 0) {
      error = "the data has a non-hex character at column " + std::to_string(hash + 2 + i);
      return false;
    }
    frame.data[i / 2] = static_cast<std::uint8_t>(hi * 16 + lo);
  }
  frame.can_dlc = static_cast<std::uint8_t>(data.size() / 2);
  return true;
}

std::string format_frame(const can_frame& frame) {
  char buf[64];
  int n = (frame.can_id & CAN_EFF_FLAG) ? std::snprintf(buf, sizeof buf, "%08X#", frame.can_id & CAN_EFF_MASK)
                                        : std::snprintf(buf, sizeof buf, "%03X#", frame.can_id & CAN_SFF_MASK);
  for (int i = 0; i < frame.can_dlc && i < 8; ++i) n += std::snprintf(buf + n, sizeof buf - n, "%02X", frame.data[i]);
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
  std::vector<can_frame> frames;
  for (; arg < argc; ++arg) {
    can_frame f;
    std::string error;
    if (!parse_frame(argv[arg], f, error)) {
      std::fprintf(stderr, "vcan-frame-probe: frame '%s': %s\n", argv[arg], error.c_str());
      return 2;
    }
    frames.push_back(f);
  }

  // The receiver is bound before anything is sent, so no frame can pass unseen.
  const int rx = open_raw(interface_name);
  if (rx < 0) return 1;
  const int tx = open_raw(interface_name);
  if (tx < 0) return 1;
  for (const can_frame& f : frames) {
    if (write(tx, &f, sizeof f) != static_cast<ssize_t>(sizeof f)) {
      std::fprintf(stderr, "vcan-frame-probe: send %s: %s\n", format_frame(f).c_str(), std::strerror(errno));
      return 1;
    }
    pollfd p{rx, POLLIN, 0};
    const int ready = poll(&p, 1, timeout_ms);
    if (ready <= 0) {
      std::fprintf(stderr, "vcan-frame-probe: %s did not come back within %d ms\n", format_frame(f).c_str(), timeout_ms);
      return 1;
    }
    can_frame got{};
    if (read(rx, &got, sizeof got) != static_cast<ssize_t>(sizeof got)) {
      std::fprintf(stderr, "vcan-frame-probe: receive: %s\n", std::strerror(errno));
      return 1;
    }
    std::printf("%s\n", format_frame(got).c_str());
  }
  close(tx);
  close(rx);
  return 0;
}
