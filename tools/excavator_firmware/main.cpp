// excavator-firmware: the controller as its own process on a SocketCAN interface. Each cycle it sends
// SYNC, waits for the plant's sensor set, computes and sends the commands. By default it runs in
// lockstep (the next cycle starts when the plant has answered or the sensor timeout expired), so a
// run is deterministic and equals the in-process run of excavator-sim; --realtime runs on absolute
// deadlines of the controller's period instead, and a run that misses them says so.
#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"
#include "output_file.hpp"

#include <atomic>
#include <csignal>
#include <exception>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/firmware_node.hpp"
#include "app/firmware_settings.hpp"
#include "app/float_environment.hpp"
#include "app/last_safe_command.hpp"
#include "app/node_io.hpp"
#include "app/realtime_setup.hpp"
#include "control/controller_registry.hpp"
#include "hal/clock.hpp"
#include "settings/section_reader.hpp"

namespace {

std::atomic<int> g_signals{0};
void on_signal(int) { g_signals.fetch_add(1); }

// Per joint; null when the firmware never tracked (a metric of no samples is not 0).
nlohmann::json per_joint(const exc::TrackingMetrics& m, bool rms) {
  if (m.samples() == 0) return nullptr;
  nlohmann::json j;
  for (int i = 0; i < 4; ++i) j[exc::kActiveNames[i]] = rms ? m.rms(i) : m.max_abs(i);
  return j;
}

std::string format_ms(double seconds) {
  char b[32];
  std::snprintf(b, sizeof b, "%g ms", seconds * 1e3);
  return b;
}

std::string percent(double fraction) {
  char b[32];
  std::snprintf(b, sizeof b, "%g %%", fraction * 100);
  return b;
}

nlohmann::json timing_json(const exc::control::PerfCounter& c) {
  if (c.count() == 0) return nullptr;
  return {{"median", c.median_us()}, {"p99", c.p99_us()}, {"p99_9", c.percentile_us(0.999)}, {"max", c.max_us()},
          {"count", c.count()}};
}

}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-firmware");  // stdout lost to a full disk is not exit 0
  // This thread runs the loop (and starts the telemetry thread): subnormals flushed before anything
  // is computed, so start-up and the loop share one arithmetic (docs/floating-point.md).
  exc::app::set_loop_float_mode();
  CLI::App app{"excavator-firmware: the controller on a SocketCAN interface (see README, docs/vcan.md)."};
  std::string iface, scene_path, controller, json_path, lcm_url;
  double duration = 0, sensor_timeout_ms = 0, startup_s = 60, max_overrun_fraction = 0.01;
  bool realtime = false, print_config = false, wait_for_start = false;
  app.add_option("--can", iface, "SocketCAN interface, e.g. vcan0 (required unless --print-config)");
  app.add_option("--scene", scene_path, "scene file (its machine, controller and task sections)")->required();
  app.add_option("--controller", controller, "the control law (default: the scene's controller.type, else adaptive):\n" +
                                                 exc::control::controller_registry().help())
      ->check(CLI::IsMember(exc::control::controller_registry().name_list()));
  app.add_option("--duration", duration, "seconds to run (default: the scene's duration)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  app.add_option("--json", json_path, "write the run's summary (ok, tracking figures, timing, deadlines) here");
  app.add_option("--lcm", lcm_url, "publish telemetry to this LCM URL (default: none)");
  app.add_option("--sensor-timeout-ms", sensor_timeout_ms,
                 "how long a cycle waits for the plant's sensor set: lockstep default 250 ms; real time default "
                 "and upper bound: the cycle's deadline less 10 % of the period")
      ->check(exc::cli::number_in({0.01, 600000}, "ms"));
  app.add_option("--startup-timeout", startup_s,
                 "how long the first cycle waits for the plant's first answer (s), in both modes")
      ->check(exc::cli::number_in({0.001, 86400}, "s"));
  app.add_flag("--realtime", realtime, "run on absolute deadlines of controller.period instead of lockstep");
  app.add_option("--max-overrun-fraction", max_overrun_fraction,
                 "real time: the run fails when its late wake-ups and skipped periods together exceed this "
                 "fraction of its cycles (default 0.01)")
      ->check(exc::cli::number_in({0, 1}, ""));
  app.add_flag("--wait-for-start", wait_for_start, "hold until an operator's start (SUPERVISOR frame, excavator-operator start)");
  app.add_flag("--print-config", print_config,
               "print the firmware's sections of the scene as it reads them, every default filled in (YAML), and exit");
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
  if (!print_config && iface.empty()) {
    std::cerr << "excavator-firmware: --can is required\n";
    return 2;
  }

  try {
    const exc::app::FirmwareSettings settings = exc::app::load_firmware_settings(scene_path);
    if (print_config) {
      std::cout << exc::settings::emit(settings.effective);
      return 0;
    }
    const exc::Model model = exc::build_model(settings.machine);
    exc::app::FirmwareNodeConfig fc;
    fc.controller = settings.controller;  // the scene's controller.type unless --controller says otherwise
    if (!controller.empty()) {
      if (settings.controller.law_given && controller != settings.controller.law) {
        std::cerr << "excavator-firmware: --controller " << controller << " conflicts with the scene's controller.type "
                  << settings.controller.law << " (" << scene_path << "); give one of them\n";
        return 2;
      }
      fc.controller.law = controller;
    }
    fc.site_map = settings.terrain;
    fc.wait_for_start = wait_for_start;
    const char* const law_name = fc.controller.law.c_str();

    const double period_s = settings.controller.period;
    const auto period_ns = static_cast<std::int64_t>(std::llround(period_s * 1e9));
    // Real time: sensors may be waited for until 10 % of the period before the next deadline, the
    // rest is the cycle's own work. A longer timeout cannot be honoured there: refused.
    const double rt_wait_ms = 0.9 * period_s * 1e3;
    if (realtime && sensor_timeout_ms > rt_wait_ms) {
      std::cerr << "excavator-firmware: --sensor-timeout-ms " << sensor_timeout_ms << " cannot be honoured with --realtime at a "
                << period_s * 1e3 << " ms period (controller.period): at most " << rt_wait_ms << " ms\n";
      return 2;
    }
    const double wait_ms = sensor_timeout_ms > 0 ? sensor_timeout_ms : (realtime ? rt_wait_ms : 250.0);

    // The summary's file is opened before the bus: a path that cannot be written costs no run.
    std::ofstream json_file;
    if (!json_path.empty()) json_file = exc::output::open_file(json_path);

    exc::app::NodeIo io;
    std::string error;
    // Real time: a full telemetry ring must not stall the loop (refused and counted); lockstep has
    // no deadline, so it waits and records every message.
    const auto overflow = realtime ? exc::telemetry::OverflowPolicy::drop_newest : exc::telemetry::OverflowPolicy::block;
    if (const int code = exc::app::open_node_io(exc::hal::Node::firmware, iface, lcm_url, overflow, io, error)) {
      std::cerr << "excavator-firmware: " << error << "\n";
      return code;
    }
    exc::hal::FirmwareCanPort port(*io.bus);
    exc::app::FirmwareNode node(model, settings.task, fc, port, io.publisher.get());
    exc::app::LastSafeCommand last_safe_command(node);

    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);
    std::string rt_notes;
    if (realtime) {
      exc::app::RealtimeRequest request;
      request.fifo_priority = 80;
      const exc::app::RealtimeSetup rt = exc::app::prepare_realtime(request);
      rt_notes = std::string(rt.memory_locked ? "memory locked" : "memory NOT locked") +
                 (rt.fifo ? ", SCHED_FIFO 80" : ", normal priority");
      if (!rt.warnings.empty()) std::fprintf(stderr, "excavator-firmware: warning: %s", rt.warnings.c_str());
    }
    const auto cycles = static_cast<std::int64_t>(std::llround((duration > 0 ? duration : settings.duration) / period_s));
    const auto wait_ns = static_cast<std::int64_t>(wait_ms * 1e6);
    const auto startup_wait_ns = static_cast<std::int64_t>(startup_s * 1e9);
    exc::hal::DeadlineSleeper sleeper(period_ns);
    std::printf("excavator-firmware: %s on %s, %lld cycles of %.3g ms, %s; sensor wait %.3g ms; floating point: %s%s%s\n",
                law_name, iface.c_str(), static_cast<long long>(cycles), period_s * 1e3,
                realtime ? "real time (absolute deadlines)" : "lockstep with the plant", wait_ms,
                exc::app::kFloatModes.name_of(exc::app::float_mode_of_thread()), rt_notes.empty() ? "" : "; ",
                rt_notes.c_str());
    std::fflush(stdout);

    std::int64_t last_wake = 0;
    bool grid_started = false;
    std::int64_t stop_cycle = -1;  // cycle of the stop request: the machine then holds, and the run ends
    for (std::int64_t k = 0; k < cycles && g_signals.load() < 2; ++k) {
      if (g_signals.load() == 1 && stop_cycle < 0) {
        // A tracking machine is brought to hold first; in any other mode there is nothing to stop.
        if (!node.tracking()) break;
        node.request_stop();
        stop_cycle = k;
        std::printf("excavator-firmware: stop requested: holding for %.2f s, then exiting\n", fc.controller.blend_time);
      }
      if (stop_cycle >= 0 && static_cast<double>(k - stop_cycle) * period_s > fc.controller.blend_time) break;
      if (realtime && grid_started) {
        sleeper.wait_next();
        const std::int64_t now = exc::hal::monotonic_now_ns();
        node.record_wakeup(now - last_wake, sleeper.overruns(), sleeper.skipped_periods());
        last_wake = now;
      }
      const std::int64_t cycle_start = exc::hal::monotonic_now_ns();
      node.begin_cycle();
      // Until the plant has answered once, a cycle waits as long as start-up takes (a slow first
      // cycle must not desynchronise the counters); afterwards the sensor wait feeds the watchdog.
      std::int64_t deadline = cycle_start + (node.has_sensors() ? wait_ns : startup_wait_ns);
      if (realtime && grid_started) deadline = std::min(deadline, sleeper.next_deadline_ns() - period_ns / 10);
      while (!node.receive()) {
        const std::int64_t left = deadline - exc::hal::monotonic_now_ns();
        if (left <= 0) break;
        io.bus->wait_readable(left);
      }
      node.end_cycle();
      if (realtime && !grid_started && node.has_sensors()) {
        // The deadline grid starts once the plant has answered: start-up is not a missed deadline.
        grid_started = true;
        last_wake = exc::hal::monotonic_now_ns();
        sleeper.start(last_wake);
      }
      const exc::control::Transition& t = node.last_transition();
      if (t.changed) {
        std::printf("excavator-firmware: cycle %llu (%.3f s): %s -> %s: %s%s%s\n",
                    static_cast<unsigned long long>(node.cycle()), node.time(), exc::control::to_string(t.from),
                    exc::control::to_string(t.to), t.reason, t.to == exc::control::Mode::safe_stop ? ": " : "",
                    t.to == exc::control::Mode::safe_stop ? node.last_fault_text() : "");
        std::fflush(stdout);
      }
    }
    // The run is over (its end, or a signal): the machine is left with its valves centred.
    node.send_safe_command(exc::app::FirmwareFault::exited);
    std::printf("excavator-firmware: last command sent: valves centred, FW_EMERGENCY %s stop (%s)\n",
                exc::app::to_string(node.emergency_sent() ? exc::app::StopKind::emergency : exc::app::StopKind::controlled),
                node.mode() == exc::control::Mode::safe_stop ? node.last_fault_text() : "firmware exited");
    node.publish_counters(true);
    if (io.publisher) io.publisher->stop();

    // The verdict: a run that never tracked, went to its safe state, or missed its deadlines failed.
    const std::uint64_t done = node.cycle();
    const std::uint64_t overruns = sleeper.overruns(), skipped = sleeper.skipped_periods();
    // Missed deadlines come first when they are there: a loop that cannot hold its period starves
    // its own sensor watchdog, so the safe stop that follows is their consequence, named after them.
    std::string failure;
    const auto add = [&failure](const std::string& reason) { failure += (failure.empty() ? "" : "; then ") + reason; };
    if (realtime && static_cast<double>(overruns + skipped) > max_overrun_fraction * static_cast<double>(done))
      add(std::to_string(overruns) + " of " + std::to_string(done) + " cycles woke after their deadline and " +
          std::to_string(skipped) + " periods were skipped (allowed together: " + percent(max_overrun_fraction) +
          " of the cycles): the loop cannot hold its " + format_ms(period_s) + " period");
    if (node.measured_tracking().samples() == 0)
      add(std::string("the firmware never tracked (mode ") + exc::control::to_string(node.mode()) + ")");
    else if (node.safe_stops() > 0)
      add(std::string("safe state: ") + node.last_fault_text());
    const bool ok = failure.empty();
    std::uint64_t telemetry_dropped = 0;
    exc::telemetry::TelemetryCounters tcn;
    if (io.publisher) {
      tcn = io.publisher->counters();
      telemetry_dropped = tcn.dropped_full_total;
    }
    const auto& c = node.control_timing();
    std::printf("excavator-firmware: %llu cycles of %.3g ms; control step median %.1f us, p99 %.1f us, max %.1f us; "
                "deadline overruns %llu, skipped periods %llu; safe stops %llu; CAN rejects %llu; telemetry dropped %llu\n",
                static_cast<unsigned long long>(done), period_s * 1e3, c.median_us(), c.p99_us(), c.max_us(),
                static_cast<unsigned long long>(overruns), static_cast<unsigned long long>(skipped),
                static_cast<unsigned long long>(node.safe_stops()), static_cast<unsigned long long>(port.rx_stats().rejected()),
                static_cast<unsigned long long>(telemetry_dropped));
    std::printf("excavator-firmware: %s%s\n", ok ? "ok" : "FAILED: ", failure.c_str());
    if (!json_path.empty()) {
      nlohmann::json j;
      j["ok"] = ok;
      if (!ok) j["failure"] = failure;
      j["controller"] = law_name;
      j["mode"] = realtime ? "realtime" : "lockstep";
      j["float_mode"] = exc::app::kFloatModes.name_of(exc::app::float_mode_of_thread());  // the loop thread's, at its end
      j["period_s"] = period_s;
      j["cycles"] = done;
      j["tracking"] = {{"rms_error", per_joint(node.measured_tracking(), true)},
                       {"max_error", per_joint(node.measured_tracking(), false)}};
      j["tracking_samples"] = node.measured_tracking().samples();
      j["control_step_us"] = timing_json(c);
      j["cycle_us"] = timing_json(node.cycle_timing());
      j["deadlines"] = {{"overruns", overruns}, {"skipped_periods", skipped},
                        {"interval_us", timing_json(node.interval_timing())}};
      j["safe_stops"] = node.safe_stops();
      j["estop"] = node.emergency_sent();  // any FW_EMERGENCY with EmergencyStop = 1, the last command included
      if (node.safe_stops() > 0) j["last_fault"] = node.last_fault_text();
      j["task_finished"] = node.trajectory_finished();
      j["can_frames_rejected"] = port.rx_stats().rejected();
      if (io.publisher) {
        nlohmann::json dropped;
        for (std::size_t i = 0; i < exc::telemetry::channel_count; ++i)
          dropped[io.publisher->channel_name(static_cast<exc::telemetry::Channel>(i))] = tcn.dropped_full[i];
        j["telemetry"] = {{"enqueued", tcn.enqueued}, {"published", tcn.published}, {"dropped", telemetry_dropped},
                          {"dropped_by_channel", dropped}, {"ring_high_water", tcn.ring_high_water},
                          {"ring_capacity", tcn.ring_capacity}, {"overflow_policy", exc::telemetry::to_string(overflow)}};
      }
      json_file << j.dump(2) << "\n";
      exc::output::finish_file(json_file, json_path);
    }
    return ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "excavator-firmware: " << e.what() << "\n";
    return 2;
  }
}
