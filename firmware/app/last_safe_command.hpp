#pragma once
// Every way out of a firmware program's loop once its node exists (end of run, SIGINT/SIGTERM, a
// second signal, an exception) leaves a safe command on the bus: valves centred and FW_EMERGENCY
// (docs/safety.md, H8). An exception unwinding through it takes the emergency stop.
#include <exception>

#include "app/firmware_node.hpp"

namespace exc::app {

class LastSafeCommand {
 public:
  explicit LastSafeCommand(FirmwareNode& node) : node_(node) {}
  LastSafeCommand(const LastSafeCommand&) = delete;
  LastSafeCommand& operator=(const LastSafeCommand&) = delete;
  ~LastSafeCommand() {
    if (!node_.safe_command_sent())
      node_.send_safe_command(std::uncaught_exceptions() > 0 ? safety::FirmwareFault::fatal_error : safety::FirmwareFault::exited);
  }

 private:
  FirmwareNode& node_;
};

}  // namespace exc::app
