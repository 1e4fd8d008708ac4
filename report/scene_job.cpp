#include "scene_job.hpp"

#include "harness/target_firmware.hpp"

#include <sys/stat.h>
#include <sys/statvfs.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <stdexcept>
#include <string_view>

#include "control/controller_registry.hpp"
#include "harness/log_volume.hpp"
#include "output_files/output_file.hpp"
#include "run_interrupt.hpp"
#include "run_report.hpp"
#include "settings/section_reader.hpp"

namespace exc::sim {

namespace fs = std::filesystem;

namespace {

// The laws registered to run by default that can drive the scene's command interface, in registration
// order; a law that cannot run the scene's task is left out, and `out` says why.
std::vector<std::string> default_controllers(const SceneBundle& bundle, std::ostream& out) {
  std::vector<std::string> names;
  for (const control::ControllerEntry& law : control::controller_registry().entries()) {
    if (law.default_run != control::DefaultRun::yes) continue;
    if (!control::interface_misfit(law, bundle.firmware.controller.command_interface).empty()) continue;
    const std::string why = law.task_misfit ? law.task_misfit(bundle.firmware.task) : "";
    if (why.empty()) {
      names.push_back(law.name);
    } else {
      out << "excavator-sim: " << bundle.name << ": " << law.name << " left out of the default controllers: " << why
          << "; --controller " << law.name << " runs it\n";
    }
  }
  return names;
}

// LCM's file provider: file://PATH?mode=w.
constexpr std::string_view kFileScheme = "file://";

// "13.2 MB": decimal units, as df -H and file managers count.
std::string human_bytes(double bytes) {
  const char* units[] = {"bytes", "kB", "MB", "GB", "TB", "PB"};
  int u = 0;
  while (bytes >= 1000 && u < 5) {
    bytes /= 1000;
    ++u;
  }
  char text[32];
  std::snprintf(text, sizeof text, u == 0 ? "%.0f %s" : "%.3g %s", bytes, units[u]);
  return text;
}

std::string ordinal_cycle(std::uint32_t every) {
  if (every <= 1) return "every cycle";
  const std::uint32_t tens = every % 100, ones = every % 10;
  const char* suffix = tens >= 11 && tens <= 13 ? "th" : ones == 1 ? "st" : ones == 2 ? "nd" : ones == 3 ? "rd" : "th";
  return "every " + std::to_string(every) + suffix + " cycle";
}

// The nearest directory of `path` that exists (the log's own may be created by the run).
fs::path existing_directory(const fs::path& path) {
  fs::path dir = fs::absolute(path).parent_path();
  std::error_code ec;
  while (!dir.empty() && !fs::is_directory(dir, ec) && dir != dir.root_path()) dir = dir.parent_path();
  return dir;
}

struct FileSystemRoom {
  std::uint64_t free = 0;       // bytes this process may still write (f_bavail)
  std::uint64_t needed = 0;     // the logs' expected bytes
  std::uint64_t reclaimed = 0;  // bytes of logs that exist and will be overwritten
  fs::path probed;              // the directory statvfs looked at
  std::vector<fs::path> logs;
};

}  // namespace

SceneJobPlan plan_scene_job(const SceneJob& job) {
  SceneJobPlan plan;
  plan.job = job;
  plan.bundle = load_scene_bundle(job.scene_path);
  const SceneBundle& bundle = plan.bundle;
  RunOptions& options = plan.options;
  options.scene_path = job.scene_path;
  options.duration_override = job.duration;
  options.progress = job.progress;
  options.log_every = job.log_every;
  options.firmware_target = job.firmware_target;
  options.interrupt = &run_interrupt();  // zero unless catch_run_interrupt's handler saw a SIGINT
  // A target without its image is refused before anything runs or is written.
  if (!job.firmware_target.empty()) {
    const std::string image = firmware_target_image(job.firmware_target);
    if (image.empty() || !std::filesystem::exists(image))
      throw std::invalid_argument("--firmware-target " + job.firmware_target + ": no firmware image" +
                                  (image.empty() ? std::string(" was built (the test build makes it; another build with -DEXC_TARGET_IMAGES=ON, after tools/install-deps test)")
                                                 : " at " + image + " (build it: cmake --build <build> --target exc_target_images)"));
  }
  // Which controllers: --controller, else the scene's controller.type, else the registry's default set
  // (the paper's comparison, and on a valve-commanded machine the industry's flow-based baseline beside it).
  const control::ControllerConfig& cc = bundle.firmware.controller;
  if (!job.controllers.empty() && cc.law_given && job.controllers != std::vector<std::string>{cc.law})
    throw std::invalid_argument("--controller conflicts with " + job.scene_path + "'s controller.type: " + cc.law +
                                "; give one of them");
  options.controllers = !job.controllers.empty() ? job.controllers
                        : cc.law_given           ? std::vector<std::string>{cc.law}
                                                 : default_controllers(bundle, std::cerr);
  check_controller_names(options.controllers);
  // A law the scene's command interface cannot carry is refused here, before the log's size is
  // stated and before anything is written, not when its run builds it.
  for (const std::string& name : options.controllers)
    if (const std::string why = control::interface_misfit(control::controller_registry().at(name), cc.command_interface);
        !why.empty())
      throw std::invalid_argument("--controller: " + why + " (" + job.scene_path + "'s controller.command_interface is " +
                                  control::kCommandInterfaces.name_of(cc.command_interface) + ")");
  plan.out_dir = job.out_dir.empty() ? fs::path("out") / bundle.name : job.out_dir;
  options.lcm_url = job.lcm_url.empty()
                        ? std::string(kFileScheme) + (fs::absolute(plan.out_dir) / "run.lcm").string() + "?mode=w"
                        : job.lcm_url;
  if (options.lcm_url.rfind(kFileScheme, 0) == 0) {
    // The path between the scheme and the options.
    const std::string rest = options.lcm_url.substr(kFileScheme.size());
    plan.log = rest.substr(0, rest.find('?'));
  }
  plan.cycles = lockstep_cycles(bundle.scene, job.duration);
  for (const std::string& name : options.controllers) {
    const LogVolume v = lockstep_log_volume(plan.cycles, "/" + name, job.log_every);
    plan.log_bytes += v.bytes;
    plan.per_cycle_bytes += v.per_cycle_bytes;
  }
  if (!options.controllers.empty()) plan.per_cycle_bytes /= options.controllers.size();  // the mean: names differ in length
  return plan;
}

void check_log_room(const std::vector<const SceneJobPlan*>& plans) {
  std::map<dev_t, FileSystemRoom> file_systems;
  for (const SceneJobPlan* plan : plans) {
    const std::string what = std::to_string(plan->options.controllers.size()) + " controller" +
                             (plan->options.controllers.size() == 1 ? "" : "s") + " x " + std::to_string(plan->cycles) +
                             " cycles, EXC_STATE, EXC_COMMAND and EXC_CONTROLLER " + ordinal_cycle(plan->job.log_every) +
                             ", " + human_bytes(static_cast<double>(plan->per_cycle_bytes)) + " per recorded cycle and controller";
    if (plan->log.empty()) {
      std::fprintf(stderr, "excavator-sim: telemetry to %s (no log file here); logged, it takes about %s (%s)\n",
                   plan->options.lcm_url.c_str(), human_bytes(static_cast<double>(plan->log_bytes)).c_str(), what.c_str());
      continue;
    }
    const fs::path dir = existing_directory(plan->log);
    struct stat st {};
    struct statvfs vfs {};
    if (::stat(dir.c_str(), &st) != 0 || ::statvfs(dir.c_str(), &vfs) != 0)
      throw std::runtime_error(dir.string() + ": cannot read its file system's free space (" + std::strerror(errno) + ")");
    FileSystemRoom& room = file_systems[st.st_dev];
    room.free = static_cast<std::uint64_t>(vfs.f_bavail) * vfs.f_frsize;
    room.probed = dir;
    room.needed += plan->log_bytes;
    room.logs.push_back(plan->log);
    std::error_code ec;
    const auto existing = fs::file_size(plan->log, ec);
    if (!ec) room.reclaimed += existing;
    std::fprintf(stderr, "excavator-sim: log %s: about %s (%llu bytes: %s); %s free on its file system\n",
                 plan->log.c_str(), human_bytes(static_cast<double>(plan->log_bytes)).c_str(),
                 static_cast<unsigned long long>(plan->log_bytes), what.c_str(),
                 human_bytes(static_cast<double>(room.free)).c_str());
  }
  for (const auto& [device, room] : file_systems) {
    if (room.needed <= room.free + room.reclaimed) continue;
    std::string logs;
    for (const fs::path& log : room.logs) logs += (logs.empty() ? "" : ", ") + log.string();
    throw std::runtime_error(
        (room.logs.size() == 1 ? "the log " + logs + " needs" : "the logs " + logs + " need") + " about " +
        human_bytes(static_cast<double>(room.needed)) + " (" + std::to_string(room.needed) + " bytes) but " +
        (room.logs.size() == 1 ? "its" : "their") + " file system (" +
        room.probed.string() + ") has " + human_bytes(static_cast<double>(room.free + room.reclaimed)) +
        " free: shorten the run (--duration), record the per-cycle channels less often (--log-every N) or write the "
        "log to another disk (--out DIR, or --lcm file://PATH?mode=w)");
  }
}

SceneJobResult run_scene_job(const SceneJobPlan& plan) {
  const SceneJob& job = plan.job;
  const SceneBundle& bundle = plan.bundle;
  SceneJobResult result;
  result.out_dir = plan.out_dir;
  // The --json file is opened before the run, so a path that cannot be written costs no run time.
  std::ofstream json_file;
  if (!job.json_path.empty()) json_file = output::open_file(job.json_path);
  fs::create_directories(result.out_dir);
  // What the run used, every default filled in: it loads back to the same run.
  output::write_file(result.out_dir / "effective.yaml", settings::emit(bundle.effective));

  result.summary = run_all(bundle, plan.options);
  print_summary(result.summary, std::cout);
  const nlohmann::json j = to_json(result.summary);
  const fs::path summary_path = result.out_dir / "summary.json";
  output::write_file(summary_path, j.dump(2) + "\n");
  if (!job.json_path.empty()) {
    json_file << j.dump(2) << "\n";
    output::finish_file(json_file, job.json_path);
  }
  result.exit_code = result.summary.interrupted ? kInterruptedExit : result.summary.all_ok ? 0 : 1;
  if (result.summary.interrupted)
    std::cerr << "excavator-sim: interrupted: " << summary_path.string() << " says so (ok false, interrupted true); "
              << (plan.log.empty() ? std::string("no log file") : "the log " + plan.log.string() + " is closed")
              << "\n";
  if (job.report && !plan.log.empty()) {
    const std::string title = bundle.name + ": " + bundle.scene.description;
    // The report reads the log the telemetry went to: <out>/run.lcm, or the file --lcm named.
    const int rc = write_report(plan.log, result.out_dir, summary_path, title);
    if (rc != 0) {
      std::cerr << "excavator-sim: the report step failed (exit " << rc << "); the log and summary are in "
                << result.out_dir.string() << "\n";
      if (result.exit_code == 0) result.exit_code = 1;
    } else {
      std::cout << "report: " << (result.out_dir / "report" / "report.md").string() << "\n";
    }
  } else if (job.report) {
    std::cerr << "excavator-sim: no report: the telemetry went to " << plan.options.lcm_url
              << ", not to a log file (log it with lcm-logger, then excavator-log report LOG)\n";
  }
  return result;
}

SceneJobResult run_scene_job(const SceneJob& job) {
  const SceneJobPlan plan = plan_scene_job(job);
  check_log_room({&plan});
  return run_scene_job(plan);
}

}  // namespace exc::sim
