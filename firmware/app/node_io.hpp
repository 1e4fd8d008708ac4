#pragma once
// What a node's process opens besides its node, the same way on both ends (excavator-firmware,
// excavator-plant): the SocketCAN interface with kernel filters for the frames this end receives,
// and the LCM telemetry publisher when a URL is given. Errors name the interface or the URL.
#include <memory>
#include <string>

#include "hal/can_protocol.hpp"
#include "hal/can_ports.hpp"
#include "hal/socketcan_bus.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::app {

struct NodeIo {
  std::unique_ptr<hal::SocketCanBus> bus;
  std::unique_ptr<telemetry::TelemetryPublisher> publisher;  // null without a URL
};

// Exit codes of the node programs for these failures.
inline constexpr int kExitBadInterface = 3;
inline constexpr int kExitBadTelemetry = 2;

// Opens both; on failure returns the exit code (kExitBad...) and sets `error`; 0 on success.
int open_node_io(hal::Node receiver, const std::string& interface, const std::string& lcm_url,
                 telemetry::OverflowPolicy overflow, NodeIo& io, std::string& error);

}  // namespace exc::app
