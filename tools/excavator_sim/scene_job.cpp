#include "scene_job.hpp"

#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string_view>

#include "control/flow_position_control.hpp"
#include "output_file.hpp"
#include "run_report.hpp"
#include "settings/section_reader.hpp"

namespace exc::sim {

namespace fs = std::filesystem;

SceneJobResult run_scene_job(const SceneJob& job) {
  SceneJobResult result;
  RunOptions options;
  options.scene_path = job.scene_path;
  options.duration_override = job.duration;
  options.progress = job.progress;
  const SceneBundle bundle = load_scene_bundle(job.scene_path);
  // Which controllers: --controller, else the scene's controller.type, else the paper's comparison
  // (and on a valve-commanded machine the industry's flow-based baseline beside it).
  const control::ControllerConfig& cc = bundle.firmware.controller;
  const std::string scene_kind = control::to_string(cc.kind);
  if (!job.controllers.empty() && cc.kind_given && job.controllers != std::vector<std::string>{scene_kind})
    throw std::invalid_argument("--controller conflicts with " + job.scene_path + "'s controller.type: " + scene_kind +
                                "; give one of them");
  const bool valves = cc.command_interface == control::CommandInterface::valve;
  const bool flow_fits = control::flow_law_fits(bundle.firmware.task);
  options.controllers = !job.controllers.empty() ? job.controllers
                        : cc.kind_given          ? std::vector<std::string>{scene_kind}
                        : valves && flow_fits    ? std::vector<std::string>{"pid", "adaptive", "flow"}
                                                 : std::vector<std::string>{"pid", "adaptive"};
  if (job.controllers.empty() && !cc.kind_given && valves && !flow_fits)
    std::cerr << "excavator-sim: " << bundle.name
              << ": flow left out of the default controllers: the task moves the swing, which flow-based control "
                 "cannot accelerate (docs/control.md); --controller flow runs it\n";
  result.out_dir = job.out_dir.empty() ? fs::path("out") / bundle.name : job.out_dir;
  // The --json file is opened before the run, so a path that cannot be written costs no run time.
  std::ofstream json_file;
  if (!job.json_path.empty()) json_file = output::open_file(job.json_path);
  fs::create_directories(result.out_dir);
  // What the run used, every default filled in: it loads back to the same run.
  output::write_file(result.out_dir / "effective.yaml", settings::emit(bundle.effective));
  // LCM's file provider: file://PATH?mode=w.
  constexpr std::string_view kFileScheme = "file://";
  options.lcm_url = job.lcm_url.empty()
                        ? std::string(kFileScheme) + (fs::absolute(result.out_dir) / "run.lcm").string() + "?mode=w"
                        : job.lcm_url;

  result.summary = run_all(bundle, options);
  print_summary(result.summary, std::cout);
  const nlohmann::json j = to_json(result.summary);
  const fs::path summary_path = result.out_dir / "summary.json";
  output::write_file(summary_path, j.dump(2) + "\n");
  if (!job.json_path.empty()) {
    json_file << j.dump(2) << "\n";
    output::finish_file(json_file, job.json_path);
  }
  result.exit_code = result.summary.all_ok ? 0 : 1;
  if (job.report && options.lcm_url.rfind(kFileScheme, 0) == 0) {
    const std::string title = bundle.name + ": " + bundle.scene.description;
    // The report reads the log the telemetry went to: <out>/run.lcm, or the file --lcm named (the
    // path between the scheme and the options).
    const std::string rest = options.lcm_url.substr(kFileScheme.size());
    const fs::path log = rest.substr(0, rest.find('?'));
    const int rc = write_report(log, result.out_dir, summary_path, title);
    if (rc != 0) {
      std::cerr << "excavator-sim: the report step failed (exit " << rc << "); the log and summary are in "
                << result.out_dir.string() << "\n";
      result.exit_code = 1;
    } else {
      std::cout << "report: " << (result.out_dir / "report" / "report.md").string() << "\n";
    }
  } else if (job.report) {
    std::cerr << "excavator-sim: no report: the telemetry went to " << options.lcm_url
              << ", not to a log file (log it with lcm-logger, then excavator-log report LOG)\n";
  }
  return result;
}

}  // namespace exc::sim
