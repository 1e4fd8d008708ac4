// excavator-plant: the simulated excavator as its own process on a SocketCAN interface. It steps
// exactly once per SYNC and answers with its sensor frames; when SYNC stops (the firmware died or
// was stopped) it holds the machine, says so on the bus (PLANT_EMERGENCY) and on stdout, and waits.
#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"

#include <atomic>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <memory>
#include <stdexcept>

#include "app/firmware_settings.hpp"
#include "app/float_environment.hpp"
#include "app/node_io.hpp"
#include "hal/can_protocol.hpp"
#include "output_files/output_file.hpp"
#include "sim_plant/plant_node.hpp"
#include "sim_plant/plant.hpp"
#include "settings/section_reader.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace {
std::atomic<bool> g_stop{false};
void on_signal(int) { g_stop = true; }
}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-plant");  // stdout lost to a full disk is not exit 0
  // This thread steps the plant (and starts the telemetry thread): subnormals flushed, as in the
  // firmware and the lockstep harness, so the two processes compute what one process computes.
  exc::app::set_loop_float_mode();
  CLI::App app{"excavator-plant: the simulated excavator on a SocketCAN interface, one step per SYNC from "
               "excavator-firmware; holds when SYNC stops (setting up vcan0 and running the two: docs/vcan.md)."};
  std::string iface, scene_path, lcm_url;
  double duration = 0, silence_ms = 500, startup_s = 120;
  bool realtime = false, print_config = false;
  // A main-valve spool stuck (as the fault campaign's spool_stuck) for the vcan safety tests.
  std::string stuck_function;
  double stuck_opening = 0, stuck_from = 0, stuck_until = 1e9;
  app.add_option("--can", iface, "SocketCAN interface, e.g. vcan0 (required unless --print-config)");
  app.add_option("--scene", scene_path, "scene file (its machine, soil, actuators, sensors, ... sections)")->required();
  app.add_option("--duration", duration,
                 "exit after this many simulated seconds (default: the scene's, or while SYNC comes on after it: "
                 "a firmware whose task is stretched, by task.efforts.fit_timing or controller.pump_pacing, runs longer)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  app.add_option("--lcm", lcm_url, "publish the machine state (EXC_STATE) to this LCM URL");
  app.add_option("--silence-ms", silence_ms, "hold after this long without SYNC (wall clock)")
      ->capture_default_str()
      ->check(exc::cli::number_in({0.01, 600000}, "ms"));
  app.add_option("--startup-timeout", startup_s, "give up if no SYNC arrives within this many seconds")
      ->capture_default_str()
      ->check(exc::cli::number_in({0.001, 86400}, "s"));
  app.add_flag("--realtime", realtime,
               "the firmware runs --realtime: a full telemetry ring drops and counts messages instead of "
               "delaying the answer to SYNC past the firmware's deadline (default: wait, lose nothing)");
  app.add_option("--stuck-spool", stuck_function, "stick this function's main-valve spool (hydraulic machine)")
      ->check(CLI::IsMember({"swing", "boom", "arm", "bucket"}));
  app.add_option("--stuck-opening", stuck_opening, "the opening the spool sticks at")->capture_default_str()->check(exc::cli::number_in({-1, 1}, ""));
  app.add_option("--stuck-from", stuck_from, "simulated time it sticks")->capture_default_str()->check(exc::cli::number_in({0, 1e9}, "s"));
  app.add_option("--stuck-until", stuck_until, "simulated time it frees (default: never)")->check(exc::cli::number_in({0, 1e9}, "s"));
  app.add_flag("--print-config", print_config,
               "print the plant's sections of the scene as it reads them, every default filled in (YAML), and exit");
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
  if (!print_config && iface.empty()) {
    std::cerr << "excavator-plant: --can is required\n";
    return 2;
  }

  try {
    exc::plant::Plant plant(exc::plant::load_scene(scene_path));
    // The firmware's sections of the same file, read as excavator-firmware reads them: a misspelt
    // key or a value out of range there is named here too, at its line, before the bus is opened,
    // rather than by the other program of the pair alone.
    if (plant.scene().has_controller || plant.scene().has_task) (void)exc::app::load_firmware_settings(scene_path);
    if (print_config) {
      std::cout << exc::settings::emit(plant.scene().effective);
      return 0;
    }
    // Bad input is named before the bus is opened, as the scene's errors are.
    if (!stuck_function.empty() && !plant.fidelity().has(exc::plant::kHydraulicCircuit))
      throw std::invalid_argument("--stuck-spool needs the hydraulic machine; the scene's actuators are not");
    exc::app::NodeIo io;
    std::string error;
    // The plant steps on SYNC and has no clock of its own, but its answer is part of the firmware's
    // cycle: in lockstep the firmware waits for it, so telemetry waits too and records everything;
    // against a real-time firmware a late answer misses the firmware's deadline (its sensor wait ends
    // 10 % of the period before it), so a full ring drops and counts, as the firmware's does.
    const auto overflow = realtime ? exc::telemetry::OverflowPolicy::drop_newest : exc::telemetry::OverflowPolicy::block;
    if (const int code = exc::app::open_node_io(exc::hal::Node::plant, iface, lcm_url, overflow, io, error)) {
      std::cerr << "excavator-plant: " << error << "\n";
      return code;
    }
    auto& bus = io.bus;
    auto& publisher = io.publisher;
    exc::hal::PlantCanPort port(*bus);
    exc::plant::PlantNode node(plant, port, publisher.get());
    exc::plant::InjectedFault stuck;
    if (!stuck_function.empty()) {
      stuck.kind = exc::plant::InjectedFault::Kind::spool_stuck;
      stuck.joint = stuck_function == "swing" ? 0 : stuck_function == "boom" ? 1 : stuck_function == "arm" ? 2 : 3;
      stuck.magnitude = stuck_opening;
    }
    bool stuck_now = false;
    std::signal(SIGINT, on_signal);
    std::signal(SIGTERM, on_signal);

    const double total = duration > 0 ? duration : plant.scene().duration;
    const auto cycles = static_cast<std::uint64_t>(std::llround(total / plant.scene().cycle));
    // Without --duration the firmware decides the run's length: it may have stretched the task past
    // the scene's duration (fit_timing, pump_pacing), which this side does not read. Past the scene's
    // cycles the plant answers every SYNC that still comes and ends once none came for --silence-ms.
    const bool follow_firmware = duration <= 0;
    // Wake every 10 ms to watch for silence: while holding, PLANT_EMERGENCY repeats at that period
    // (IfActive in the DBC).
    const std::int64_t slice_ns = exc::hal::kEmergencyRepeatCycles * exc::hal::kCyclePeriodNs;
    double silent_ms = 0;
    bool announced = false;
    std::printf("excavator-plant: %s on %s, %llu cycles%s, waiting for SYNC\n", plant.scene().name.c_str(),
                iface.c_str(), static_cast<unsigned long long>(cycles), follow_firmware ? " or as many as the firmware runs" : "");
    std::fflush(stdout);
    while (!g_stop && (node.steps() < cycles || follow_firmware)) {
      const double t = static_cast<double>(node.steps()) * plant.scene().cycle;
      if (stuck.kind != exc::plant::InjectedFault::Kind::none && (t >= stuck_from && t < stuck_until) != stuck_now) {
        stuck_now = !stuck_now;
        node.set_fault(stuck_now ? stuck : exc::plant::InjectedFault{});
        std::printf("excavator-plant: %s spool %s at %.3f s\n", stuck_function.c_str(), stuck_now ? "stuck" : "freed", t);
        std::fflush(stdout);
      }
      if (node.wait(slice_ns)) {
        silent_ms = 0;
        if (announced) {
          std::printf("excavator-plant: SYNC is back at step %llu\n", static_cast<unsigned long long>(node.steps()));
          std::fflush(stdout);
          announced = false;
        }
        if (node.failed()) {
          std::printf("excavator-plant: stopped: %s\n", plant.status().text());
          return 4;
        }
        continue;
      }
      silent_ms += slice_ns * 1e-6;
      // Following the firmware past the scene's end: silent as long as would make it hold, its run is over.
      if (node.steps() >= cycles && silent_ms >= silence_ms) break;
      if (node.steps() == 0 && silent_ms > startup_s * 1e3) {
        std::fprintf(stderr, "excavator-plant: no SYNC on %s within %.0f s; is excavator-firmware running?\n",
                     iface.c_str(), startup_s);
        return 5;
      }
      if (node.steps() > 0 && silent_ms >= silence_ms) node.hold_for_silence();  // entry, then every slice
      if (node.steps() > 0 && silent_ms >= silence_ms && !announced) {
        std::printf("excavator-plant: no SYNC for %.0f ms after step %llu: hold (valves centred, machine braked)\n",
                    silent_ms, static_cast<unsigned long long>(node.steps()));
        std::fflush(stdout);
        announced = true;
      }
    }
    node.publish_counters();
    exc::telemetry::TelemetryCounters tc;
    if (publisher) {
      publisher->stop();
      tc = publisher->counters();
    }
    std::printf("excavator-plant: %llu steps, %.3f s simulated, %llu holds, CAN rejects %llu; floating point: %s; "
                "telemetry (%s) %llu messages, %llu dropped, ring high water %zu of %zu\n",
                static_cast<unsigned long long>(node.steps()), plant.state().time,
                static_cast<unsigned long long>(node.holds()), static_cast<unsigned long long>(port.rx_stats().rejected()),
                exc::app::kFloatModes.name_of(exc::app::float_mode_of_thread()), exc::telemetry::to_string(overflow),
                static_cast<unsigned long long>(tc.published),
                static_cast<unsigned long long>(tc.dropped_full_total), tc.ring_high_water, tc.ring_capacity);
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "excavator-plant: " << e.what() << "\n";
    return 2;
  }
}
