// excavator-firmware: the controller as its own process on a SocketCAN interface. Each cycle it sends
// SYNC, waits for the plant's sensor set, computes and sends the commands. By default it runs in
// lockstep (the next cycle starts when the plant has answered or the sensor timeout expired), so a
// run is deterministic and equals the in-process run of excavator-sim; --realtime runs on absolute
// deadlines of the controller's period instead, and a run that misses them says so.
// --write-settings-blob writes, instead of running, what the firmware's image runs the scene from
// (app/settings_blob.hpp) and exits.
#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"
#include "output_file.hpp"

#include <atomic>
#include <csignal>
#include <exception>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <vector>

#include "app/control_step.hpp"
#include "app/firmware_node.hpp"
#include "app/firmware_runner.hpp"
#include "app/firmware_settings.hpp"
#include "app/float_environment.hpp"
#include "app/last_safe_command.hpp"
#include "app/node_io.hpp"
#include "app/realtime_setup.hpp"
#include "app/run_summary.hpp"
#include "app/settings_blob.hpp"
#include "control/controller_registry.hpp"
#include "settings/section_reader.hpp"

namespace {

std::atomic<int> g_signals{0};
void on_signal(int) { g_signals.fetch_add(1); }

// The plant's sections the scene file gives ("soil, actuators"), "none given" without one.
std::string plant_sections_in(const std::string& scene_path) {
  const exc::settings::Document scene = exc::settings::Document::load(scene_path);
  std::string names;
  for (const std::string& section : exc::kPlantSceneSections)
    if (scene.root()[section]) names += (names.empty() ? "" : ", ") + section;
  return names.empty() ? "none given" : names;
}

}  // namespace

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-firmware");  // stdout lost to a full disk is not exit 0
  // This thread runs the loop (and starts the telemetry thread): subnormals flushed before anything
  // is computed, so start-up and the loop share one arithmetic (docs/floating-point.md).
  exc::app::set_loop_float_mode();
  CLI::App app{"excavator-firmware: the controller on a SocketCAN interface (see README, docs/vcan.md)."};
  std::string iface, scene_path, controller, json_path, lcm_url, blob_path;
  double duration = 0, sensor_timeout_ms = 0, startup_s = 60, max_overrun_fraction = 0.01;
  bool realtime = false, print_config = false, wait_for_start = false;
  app.add_option("--can", iface, "SocketCAN interface, e.g. vcan0 (required unless --print-config or --write-settings-blob)");
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
               "print the firmware's sections of the scene as it reads them, every default filled in (YAML), and exit "
               "(of the plant's sections only the keys are checked: a misspelt one is named)");
  app.add_option("--write-settings-blob", blob_path,
                 "write the settings blob the firmware's image runs the scene from (its nominal machine, controller, "
                 "task and run length, with --controller, --duration and --wait-for-start; docs/programs.md) to this "
                 "file, and exit");
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
  if (!print_config && blob_path.empty() && iface.empty()) {
    std::cerr << "excavator-firmware: --can is required\n";
    return 2;
  }

  try {
    const exc::app::FirmwareSettings settings = exc::app::load_firmware_settings(scene_path);
    if (print_config) {
      std::cout << exc::settings::emit(settings.effective);
      // The firmware links no plant code: of the plant's sections it checks the keys, not the values.
      // Said, so that exit 0 is not taken for a check of the whole scene.
      std::cerr << "excavator-firmware: the firmware's sections printed; the plant's (" << plant_sections_in(scene_path)
                << ") checked for unknown keys only, their values read and checked by excavator-plant --print-config --scene "
                << scene_path << " (or excavator-sim config " << scene_path << ")\n";
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
    // The law built once before anything is written or the bus is opened: a law the scene's command
    // interface cannot carry (--controller flow on an effort-actuated scene), or gains the law refuses,
    // are bad input, named as the scene's errors are, whether or not the interface exists.
    try {
      exc::app::check_control_law(model, fc.controller);
    } catch (const std::exception& e) {
      std::cerr << "excavator-firmware: " << e.what() << " (" << scene_path << ")\n";
      return 2;
    }
    fc.site_map = settings.terrain;
    fc.wait_for_start = wait_for_start;
    const char* const law_name = fc.controller.law.c_str();
    if (!blob_path.empty()) {
      const std::vector<std::uint8_t> blob = exc::app::encode_settings_blob(exc::app::image_settings(settings, fc, duration));
      std::ofstream blob_file = exc::output::open_file(blob_path);
      blob_file.write(reinterpret_cast<const char*>(blob.data()), static_cast<std::streamsize>(blob.size()));
      exc::output::finish_file(blob_file, blob_path);
      std::printf("excavator-firmware: %s: the settings blob of %s (%s), %zu bytes\n", blob_path.c_str(), settings.name.c_str(),
                  law_name, blob.size());
      return 0;
    }

    const double period_s = settings.controller.period;
    const auto period_ns = static_cast<std::int64_t>(std::llround(period_s * 1e9));
    // Real time: a longer sensor wait than the runner can honour is refused.
    const double rt_wait_ms = static_cast<double>(exc::app::realtime_sensor_wait_limit_ns(period_ns)) * 1e-6;
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
    exc::app::RunnerOptions run;
    run.cycles = static_cast<std::int64_t>(std::llround((duration > 0 ? duration : settings.duration) / period_s));
    run.period_ns = period_ns;
    run.realtime = realtime;
    run.sensor_wait_ns = static_cast<std::int64_t>(wait_ms * 1e6);
    run.startup_wait_ns = static_cast<std::int64_t>(startup_s * 1e9);
    run.max_overrun_fraction = max_overrun_fraction;
    run.stop_hold_s = fc.controller.actuation.blend_time;
    std::printf("excavator-firmware: %s on %s, %lld cycles of %.3g ms, %s; sensor wait %.3g ms; floating point: %s%s%s\n",
                law_name, iface.c_str(), static_cast<long long>(run.cycles), period_s * 1e3,
                realtime ? "real time (absolute deadlines)" : "lockstep with the plant", wait_ms,
                exc::app::kFloatModes.name_of(exc::app::float_mode_of_thread()), rt_notes.empty() ? "" : "; ",
                rt_notes.c_str());
    std::fflush(stdout);

    const exc::app::RunnerOutcome outcome = exc::app::run_firmware(node, *io.bus, run, g_signals, stdout);
    if (io.publisher) io.publisher->stop();
    const exc::app::RunContext context{node,     outcome, law_name, realtime, period_s, port.rx_stats().rejected(),
                                       io.publisher.get(), overflow};
    exc::app::print_run_summary(context, stdout);
    if (!json_path.empty()) {
      json_file << exc::app::run_summary_json(context).dump(2) << "\n";
      exc::output::finish_file(json_file, json_path);
    }
    return outcome.ok ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "excavator-firmware: " << e.what() << "\n";
    return 2;
  }
}
