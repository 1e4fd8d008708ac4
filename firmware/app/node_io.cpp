#include "app/node_io.hpp"

namespace exc::app {

int open_node_io(hal::Node receiver, const std::string& interface, const std::string& lcm_url,
                 telemetry::OverflowPolicy overflow, NodeIo& io, std::string& error) {
  std::uint32_t ids[32];
  const std::size_t n = hal::receive_ids(receiver, ids, 32);
  io.bus = hal::SocketCanBus::open(interface, ids, n, error);
  if (!io.bus) return kExitBadInterface;
  if (lcm_url.empty()) return 0;
  telemetry::TelemetryConfig tc;
  tc.lcm_url = lcm_url;
  tc.overflow = overflow;
  io.publisher = std::make_unique<telemetry::TelemetryPublisher>(tc);
  if (!io.publisher->start(&error)) {
    error = "--lcm: " + error;
    return kExitBadTelemetry;
  }
  return 0;
}

}  // namespace exc::app
