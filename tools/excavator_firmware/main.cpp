// excavator-firmware: the controller as its own process on a SocketCAN interface. Each cycle it sends
// SYNC, waits for the plant's sensor set, computes and sends the commands. By default it runs in
// lockstep (the next cycle starts when the plant has answered or the sensor timeout expired), so a
// run is deterministic and equals the in-process run of excavator-sim; --realtime runs on absolute
// 1 ms deadlines instead.
#include <CLI/CLI.hpp>

#include <sched.h>
#include <sys/mman.h>

#include <atomic>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/firmware_node.hpp"
#include "app/firmware_settings.hpp"
#include "hal/clock.hpp"
#include "hal/socketcan_bus.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }

void try_realtime() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0)
    std::fprintf(stderr, "excavator-firmware: warning: mlockall refused (%s); page faults may add latency\n",
                 std::strerror(errno));
  sched_param p{};
  p.sched_priority = 80;
  if (sched_setscheduler(0, SCHED_FIFO, &p) != 0)
    std::fprintf(stderr, "excavator-firmware: warning: SCHED_FIFO refused (%s); running at normal priority\n",
                 std::strerror(errno));
}

nlohmann::json per_joint(const exc::TrackingMetrics& m, bool rms) {
  nlohmann::json j;
  for (int i = 0; i < 4; ++i) j[exc::kActiveNames[i]] = rms ? m.rms(i) : m.max_abs(i);
  return j;
}
}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"excavator-firmware: the controller on a SocketCAN interface (see README)."};
  std::string iface, scene_path, controller = "adaptive", json_path, lcm_url;
  double duration = 0, sensor_timeout_ms = 250;
  double startup_s = 60;
  bool realtime = false;
  app.add_option("--can", iface, "SocketCAN interface, e.g. vcan0")->required();
  app.add_option("--scene", scene_path, "scene file (task, controller section, machine)")->required();
  app.add_option("--controller", controller, "pid, adaptive or slotine_li")
      ->check(CLI::IsMember({"pid", "adaptive", "slotine_li"}));
  app.add_option("--duration", duration, "cycles to run, in seconds (default: the scene's duration)")
      ->check(CLI::PositiveNumber);
  app.add_option("--json", json_path, "write the run's summary (tracking figures, timing) here");
  app.add_option("--lcm", lcm_url, "publish telemetry to this LCM URL (default: none)");
  app.add_option("--sensor-timeout-ms", sensor_timeout_ms,
                 "lockstep: how long a cycle waits for the plant's sensor set (wall clock)")
      ->check(CLI::PositiveNumber);
  app.add_option("--startup-timeout", startup_s,
                 "lockstep: how long the first cycle waits for the plant's first answer (s)")
      ->check(CLI::PositiveNumber);
  app.add_flag("--realtime", realtime, "run on absolute 1 ms deadlines instead of lockstep");
  CLI11_PARSE(app, argc, argv);

  try {
    const exc::app::FirmwareSettings settings = exc::app::load_firmware_settings(scene_path);
    const exc::Model model = exc::build_model(settings.machine);
    std::uint32_t ids[32];
    const std::size_t n = exc::hal::receive_ids(exc::hal::Node::firmware, ids, 32);
    std::string error;
    auto bus = exc::hal::SocketCanBus::open(iface, ids, n, error);
    if (!bus) {
      std::cerr << "excavator-firmware: " << error << "\n";
      return 3;
    }
    std::unique_ptr<exc::telemetry::TelemetryPublisher> publisher;
    if (!lcm_url.empty()) {
      exc::telemetry::TelemetryConfig tc;
      tc.lcm_url = lcm_url;
      // Real time: a full ring must not stall the loop, so it refuses and counts (reported below);
      // lockstep has no deadline, so it waits and records every message.
      tc.overflow = realtime ? exc::telemetry::OverflowPolicy::drop_newest : exc::telemetry::OverflowPolicy::block;
      publisher = std::make_unique<exc::telemetry::TelemetryPublisher>(tc);
      if (!publisher->start(&error)) {
        std::cerr << "excavator-firmware: --lcm: " << error << "\n";
        return 2;
      }
    }
    exc::hal::FirmwareCanPort port(*bus);
    exc::app::FirmwareNodeConfig fc;
    fc.kind = controller == "pid" ? exc::control::ControllerKind::pid
              : controller == "slotine_li" ? exc::control::ControllerKind::slotine_li
                                           : exc::control::ControllerKind::adaptive;
    fc.controller = settings.controller;
    fc.terrain_height = settings.terrain_height;
    exc::app::FirmwareNode node(model, settings.task, fc, port, publisher.get());

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    if (realtime) try_realtime();
    const double cycle_s = settings.controller.period;
    const auto cycles = static_cast<std::int64_t>(std::llround((duration > 0 ? duration : settings.duration) / cycle_s));
    const auto wait_ns = static_cast<std::int64_t>(realtime ? 0.8 * cycle_s * 1e9 : sensor_timeout_ms * 1e6);
    const auto startup_wait_ns = static_cast<std::int64_t>(startup_s * 1e9);
    exc::hal::DeadlineSleeper sleeper(static_cast<std::int64_t>(std::llround(cycle_s * 1e9)));
    sleeper.start(exc::hal::monotonic_now_ns());
    std::printf("excavator-firmware: %s on %s, %lld cycles, %s\n", controller.c_str(), iface.c_str(),
                static_cast<long long>(cycles), realtime ? "real time (1 ms deadlines)" : "lockstep with the plant");
    std::fflush(stdout);
    for (std::int64_t k = 0; k < cycles && !g_stop; ++k) {
      if (realtime) sleeper.wait_next();
      node.begin_cycle();
      // Until the plant has answered once, lockstep waits as long as start-up takes (a slow first
      // cycle must not desynchronise the counters); afterwards the sensor timeout feeds the watchdog.
      const std::int64_t wait = (realtime || node.has_sensors()) ? wait_ns : startup_wait_ns;
      const std::int64_t deadline = exc::hal::monotonic_now_ns() + wait;
      while (!node.receive()) {
        const std::int64_t left = deadline - exc::hal::monotonic_now_ns();
        if (left <= 0) break;
        bus->wait_readable(left);
      }
      node.end_cycle();
      const exc::control::Transition& t = node.last_transition();
      if (t.changed) {
        std::printf("excavator-firmware: cycle %llu (%.3f s): %s -> %s: %s\n",
                    static_cast<unsigned long long>(node.cycle()), node.time(), exc::control::to_string(t.from),
                    exc::control::to_string(t.to), t.reason);
        std::fflush(stdout);
      }
    }
    node.publish_counters();
    if (publisher) publisher->stop();
    const auto& c = node.control_timing();
    std::printf("excavator-firmware: %llu cycles; control step median %.1f us, p99 %.1f us, max %.1f us; "
                "deadline overruns %llu; safe stops %llu; CAN rejects %llu\n",
                static_cast<unsigned long long>(node.cycle()), c.median_us(), c.p99_us(), c.max_us(),
                static_cast<unsigned long long>(sleeper.overruns()), static_cast<unsigned long long>(node.safe_stops()),
                static_cast<unsigned long long>(port.rx_stats().rejected()));
    if (!json_path.empty()) {
      nlohmann::json j;
      j["controller"] = controller;
      j["cycles"] = node.cycle();
      j["tracking"] = {{"rms_error", per_joint(node.measured_tracking(), true)},
                       {"max_error", per_joint(node.measured_tracking(), false)}};
      j["control_step_us"] = {{"median", c.median_us()}, {"p99", c.p99_us()}, {"max", c.max_us()}};
      j["safe_stops"] = node.safe_stops();
      j["can_frames_rejected"] = port.rx_stats().rejected();
      if (publisher) {
        const exc::telemetry::TelemetryCounters tcn = publisher->counters();
        nlohmann::json dropped;
        for (std::size_t i = 0; i < exc::telemetry::channel_count; ++i)
          dropped[publisher->channel_name(static_cast<exc::telemetry::Channel>(i))] = tcn.dropped_full[i];
        j["telemetry"] = {{"enqueued", tcn.enqueued}, {"published", tcn.published},
                          {"dropped", tcn.dropped_full_total}, {"dropped_by_channel", dropped},
                          {"ring_high_water", tcn.ring_high_water}, {"ring_capacity", tcn.ring_capacity},
                          {"overflow_policy", exc::telemetry::to_string(tcn.dropped_full_total ? exc::telemetry::OverflowPolicy::drop_newest : (realtime ? exc::telemetry::OverflowPolicy::drop_newest : exc::telemetry::OverflowPolicy::block))}};
      }
      std::ofstream(json_path) << j.dump(2) << "\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "excavator-firmware: " << e.what() << "\n";
    return 2;
  }
}
