// excavator-operator: sends operator commands to the firmware as SUPERVISOR frames on a SocketCAN
// interface (one frame for start, stop, ack; a stream of them for keep-alive), as an operator station or a remote e-stop kit would: start (a firmware run with
// --wait-for-start begins its task), stop (a controlled stop that latches like a fault) or ack
// (acknowledges a latched stop; the firmware holds where the machine is once its condition is gone);
// or keep-alive: Command none every --period until its --duration ends or a signal, the monitored
// link of a remote station (the firmware stops the machine when it falls silent, supervisor_timeout).
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdint>
#include <cstdio>
#include <map>
#include <string>

#include "hal/can_ports.hpp"
#include "hal/can_protocol.hpp"
#include "hal/clock.hpp"
#include "hal/socketcan_bus.hpp"
#include "option_checks.hpp"

namespace {

volatile std::sig_atomic_t g_stop = 0;
extern "C" void on_signal(int) { g_stop = 1; }

// The command words a person types, and what each sends.
const std::map<std::string, exc::hal::SupervisorCommand> kCommands{
    {"start", exc::hal::SupervisorCommand::start},
    {"stop", exc::hal::SupervisorCommand::stop},
    {"ack", exc::hal::SupervisorCommand::acknowledge},
    {"acknowledge", exc::hal::SupervisorCommand::acknowledge},
    {"keep-alive", exc::hal::SupervisorCommand::none},
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "excavator-operator: an operator station: sends the firmware its commands as SUPERVISOR frames "
      "(hal/excavator.dbc) on a SocketCAN interface: one frame for start, stop and ack, one every --period for "
      "keep-alive.\n  start  a firmware run with --wait-for-start begins its task\n  stop   a controlled "
      "stop (valves centred), latched until acknowledged\n  ack    acknowledges a latched stop (also: acknowledge)\n"
      "  keep-alive  Command none every --period until --duration or SIGINT/SIGTERM: a monitored link; once the "
      "firmware has heard one, silence for its controller.supervisor_timeout (0.5 s) stops the machine"};
  std::string iface, command_word;
  int counter = 0;
  double period = 0.1, duration = 0;
  app.add_option("--can", iface, "SocketCAN interface, e.g. vcan0 (MTU 72: CAN FD)")->required();
  app.add_option("--counter", counter,
                 "the frame's rolling counter, 0..15 (default 0: the firmware takes a frame more than 5 ms after "
                 "the previous SUPERVISOR as a new sequence, so each run of this program is heard)")
      ->check(exc::cli::count_in(0, 15));
  app.add_option("--period", period, "keep-alive: seconds between frames")
      ->capture_default_str()
      ->check(exc::cli::number_in({0.005, 10}, "s"));
  app.add_option("--duration", duration, "keep-alive: seconds to send for (default 0: until SIGINT or SIGTERM)")
      ->check(exc::cli::number_in({0, 1e6}, "s"));
  app.add_option("command", command_word, "start, stop, ack or keep-alive")->required();
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;

  const auto found = kCommands.find(command_word);
  if (found == kCommands.end()) {
    std::fprintf(stderr, "excavator-operator: command '%s' is not one of start, stop, ack (or acknowledge), keep-alive\n",
                 command_word.c_str());
    return 2;
  }
  std::string error;
  // This end receives nothing it needs: the filter passes only other stations' SUPERVISOR frames.
  const std::uint32_t ids[] = {exc::hal::can_id::supervisor};
  auto bus = exc::hal::SocketCanBus::open(iface, ids, 1, error);
  if (bus == nullptr) {
    std::fprintf(stderr, "excavator-operator: %s\n", error.c_str());
    return 3;
  }
  exc::hal::OperatorCanPort station(*bus, static_cast<std::uint8_t>(counter));
  if (found->second == exc::hal::SupervisorCommand::none) {
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::printf("excavator-operator: SUPERVISOR keep-alive every %g s on %s%s\n", period, iface.c_str(),
                duration > 0 ? "" : " until SIGINT or SIGTERM");
    std::fflush(stdout);
    exc::hal::DeadlineSleeper sleeper(static_cast<std::int64_t>(period * 1e9));
    const std::int64_t start = exc::hal::monotonic_now_ns();
    sleeper.start(start);
    std::uint64_t sent = 0;
    while (g_stop == 0 && (duration <= 0 || exc::hal::monotonic_now_ns() - start < static_cast<std::int64_t>(duration * 1e9))) {
      if (!station.send(exc::hal::SupervisorCommand::none)) {
        std::fprintf(stderr, "excavator-operator: %s: keep-alive %llu could not be queued (interface down or its queue full)\n",
                     iface.c_str(), static_cast<unsigned long long>(sent + 1));
        return 1;
      }
      ++sent;
      sleeper.wait_next();
    }
    std::printf("excavator-operator: %llu keep-alive frames sent; %s\n", static_cast<unsigned long long>(sent),
                g_stop != 0 ? "stopped by a signal (the firmware will stop the machine after its timeout)" : "duration over");
    return 0;
  }
  if (!station.send(found->second)) {
    std::fprintf(stderr, "excavator-operator: %s: the SUPERVISOR frame could not be queued (interface down or its queue full)\n",
                 iface.c_str());
    return 1;
  }
  std::printf("excavator-operator: SUPERVISOR %s (Command %u, counter %d) sent on %s\n", exc::hal::to_string(found->second),
              static_cast<unsigned>(found->second), counter, iface.c_str());
  return 0;
}
