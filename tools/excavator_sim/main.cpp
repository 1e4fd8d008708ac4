// excavator-sim: the main job. Runs the firmware and the plant in one process over the in-memory
// CAN bus (the same frames as on a real bus), once per controller, logs telemetry with LCM, and
// writes the summary (stdout and JSON), the CSVs, the plots and a report page.
#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "app/float_environment.hpp"
#include "control/controller_registry.hpp"
#include "report/in_process_run.hpp"
#include "output_files/output_file.hpp"
#include "sweep/robustness.hpp"
#include "report/paper_report.hpp"
#include "report/run_interrupt.hpp"
#include "report/run_report.hpp"
#include "report/scene_job.hpp"
#include "settings/section_reader.hpp"
#include "sweep/sweep.hpp"
#include "telemetry/telemetry_channels.hpp"

namespace fs = std::filesystem;

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-sim");  // stdout lost to a full disk is not exit 0
  // Start-up and every run in the loop's floating-point mode, as excavator-firmware and excavator-plant
  // run (run_lockstep sets it again for each run; docs/floating-point.md).
  exc::app::set_loop_float_mode();
  CLI::App app{
      "excavator-sim: runs the firmware against the simulated excavator over the in-memory CAN bus.\n"
      "  excavator-sim run scenes/dig.yaml            PID and adaptive, summary, log, plots, report\n"
      "  excavator-sim run scenes/dig.yaml --controller adaptive --json out.json\n"
      "  excavator-sim robustness scenes/dig.yaml     the same with wrong masses, noise, delay, stiffer soil\n"
      "  excavator-sim sweep SPEC --shard I/N         one shard of a sweep; sweep-merge SPEC FILES: its table and charts\n"
      "  excavator-sim paper --out out/paper          the paper's Figs. 4-12, then the dig through the valves\n"
      "  excavator-sim config scenes/dig.yaml         the scene's effective configuration (every default filled in)"};
  app.require_subcommand(1);
  auto* run = app.add_subcommand("run", "run a scene with one or more controllers");
  std::string scene_path;
  std::vector<std::string> controllers;
  std::string out_dir;
  std::string json_path;
  std::string lcm_url;
  double duration = 0;
  bool no_report = false;
  bool quiet = false;
  run->add_option("scene", scene_path, "scene file (YAML), e.g. scenes/dig.yaml")->required();
  run->add_option("--controller", controllers,
                  "controller(s) to run (default: the scene's controller.type, else pid and adaptive, and flow on a "
                  "valve-commanded scene whose task holds the swing):\n" + exc::control::controller_registry().help())
      ->delimiter(',');
  run->add_option("--out", out_dir, "output directory (default: out/<scene name>)");
  run->add_option("--json", json_path, "also write the summary as JSON to this file");
  run->add_option("--lcm", lcm_url,
                  "LCM provider for telemetry (default: file://<out>/run.lcm?mode=w; "
                  "live: udpm://239.255.76.67:7667?ttl=0)");
  run->add_option("--duration", duration, "simulated seconds (default: the scene's duration)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  std::uint32_t log_every = 1;
  const std::string log_every_help =
      "record the per-cycle channels (EXC_STATE, EXC_COMMAND, EXC_CONTROLLER) every Nth cycle only, for a long "
      "run's log (default 1: every cycle; the other channels are always whole)";
  run->add_option("--log-every", log_every, log_every_help)
      ->check(exc::cli::count_in(1, exc::telemetry::kMaxPerCycleEvery));
  std::string firmware_target;
  run->add_option("--firmware-target", firmware_target,
                  "run the firmware on an emulated processor against the plant (processor in the loop): cortex-m7, its "
                  "image under QEMU (docs/target.md); the summary adds the image's instructions per cycle and per stage")
      ->check(CLI::IsMember({"cortex-m7"}));
  run->add_flag("--no-report", no_report, "skip the CSV export, plots and report page");
  run->add_flag("--quiet", quiet, "no progress output");

  auto* robust = app.add_subcommand(
      "robustness", "run a scene with the controller's model, sensors or soil made wrong on purpose: the variants of "
                    "a sweep spec (default sweeps/robustness.yaml: model mass -20 % and +20 %, sensor noise, 2 cycles "
                    "of sensor delay, 3x stiffer soil, all at once)");
  std::string robust_scene, robust_json, robust_out, robust_spec = EXC_ROBUSTNESS_SPEC;
  bool robust_no_plots = false;
  std::vector<std::string> robust_controllers;
  double robust_duration = 0;
  bool robust_quiet = false;
  robust->add_option("scene", robust_scene, "scene file (YAML), e.g. scenes/dig.yaml (default: the spec's)");
  robust->add_option("--spec", robust_spec, "the sweep spec whose variants run")->capture_default_str();
  robust->add_option("--controller", robust_controllers,
                     "controller(s): " + exc::control::controller_registry().names() + " (default: the spec's, pid and adaptive)")
      ->delimiter(',');
  robust->add_option("--json", robust_json, "write the table as JSON to this file");
  robust->add_option("--duration", robust_duration, "simulated seconds per run (default: the scene's duration)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  robust->add_flag("--quiet", robust_quiet, "no progress output");
  robust->add_option("--out", robust_out,
                     "output directory for robustness.json and robustness.png (default: out/<scene name>-robustness)");
  robust->add_flag("--no-plots", robust_no_plots, "skip robustness.png");
  auto* paper = app.add_subcommand(
      "paper", "the paper's whole figure set: the free-motion scene (Figs. 4-7) and the digging scene (Figs. 8-12) with "
               "the paper's force actuators, each with PID and adaptive, then the same dig through a hydraulic "
               "machine's valves with PID, adaptive and flow-based control; their reports, and one page with every "
               "figure under the paper's number and the hydraulic machine's figures");
  std::string paper_free = "scenes/paper_free_motion.yaml", paper_dig = "scenes/paper_dig.yaml",
              paper_hydraulic = "scenes/dig.yaml", paper_out = "out/paper";
  double paper_duration = 0;
  bool paper_quiet = false;
  paper->add_option("--free-motion", paper_free, "the free-motion scene (default: scenes/paper_free_motion.yaml)");
  paper->add_option("--dig", paper_dig, "the digging scene (default: scenes/paper_dig.yaml)");
  paper->add_option("--hydraulic-dig", paper_hydraulic, "the dig through the valves (default: scenes/dig.yaml)");
  paper->add_option("--out", paper_out,
                    "output directory (default: out/paper): report.md, free_motion/, dig/, hydraulic_dig/");
  paper->add_option("--duration", paper_duration, "simulated seconds of each scene (default: each scene's)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  std::uint32_t paper_log_every = 1;
  paper->add_option("--log-every", paper_log_every, log_every_help)
      ->check(exc::cli::count_in(1, exc::telemetry::kMaxPerCycleEvery));
  paper->add_flag("--quiet", paper_quiet, "no progress output");
  auto* sweep = app.add_subcommand(
      "sweep", "run a sweep's cases (all, or one shard of them for GNU parallel or a Slurm job array) into a JSON-lines "
               "file; spec format: sweep/sweep.hpp and docs/sweeps.md");
  std::string sweep_spec, sweep_shard = "0/1", sweep_out;
  bool sweep_quiet = false;
  sweep->add_option("spec", sweep_spec, "sweep spec (YAML)")->required();
  sweep->add_option("--shard", sweep_shard, "I/N: run cases I, I+N, I+2N, ... (default 0/1: every case)");
  sweep->add_option("--out", sweep_out, "the shard's result file (default: out/sweep/shard-I-of-N.jsonl)");
  sweep->add_flag("--quiet", sweep_quiet, "no progress line (it is shown only on a terminal: k of N cases, elapsed, time left)");
  bool sweep_check = false;
  sweep->add_flag("--check", sweep_check, "read and check the spec, print its number of cases, run none");
  auto* merge = app.add_subcommand("sweep-merge", "merge shard files into sweep.csv, sweep.json and the spec's charts; names missing cases and shard files");
  std::string merge_spec, merge_out = "out/sweep";
  std::vector<std::string> merge_files;
  merge->add_option("spec", merge_spec, "the sweep spec the shards ran")->required();
  merge->add_option("shards", merge_files, "shard result files")->required();
  merge->add_option("--out", merge_out, "output directory (default out/sweep)");
  bool merge_no_charts = false;
  merge->add_flag("--no-charts", merge_no_charts, "the table and summary only (no robustness or stability chart)");
  auto* config = app.add_subcommand(
      "config", "print the scene's effective configuration as YAML: both sides' sections with every default filled in "
                "(the machine as an absolute path); it loads back to the same run");
  std::string config_scene;
  config->add_option("scene", config_scene, "scene file (YAML), e.g. scenes/dig.yaml")->required();
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;

  if (config->parsed()) {
    try {
      std::cout << exc::settings::emit(exc::sim::load_scene_bundle(config_scene).effective);
      return 0;
    } catch (const std::exception& e) {
      std::cerr << "excavator-sim: " << e.what() << "\n";
      return 2;
    }
  }

  if (sweep->parsed() || merge->parsed()) {
    try {
      if (merge->parsed()) {
        const exc::sim::SweepSpec spec = exc::sim::load_sweep_spec(merge_spec);
        std::vector<fs::path> files(merge_files.begin(), merge_files.end());
        const exc::sim::MergeOutcome merged = exc::sim::merge_sweep(spec, files, merge_out, !merge_no_charts);
        std::cout << "sweep: " << (fs::path(merge_out) / "sweep.csv").string() << (merged.complete ? "" : " (cases missing)")
                  << (merged.charts_ok ? "" : " (a chart failed)") << (merged.consistent ? "" : " (records conflict)") << "\n";
        return merged.ok() ? 0 : 1;
      }
      int shard = 0, shards = 1;
      if (!exc::sim::parse_shard(sweep_shard, shard, shards)) {
        std::cerr << "excavator-sim sweep: --shard '" << sweep_shard << "': must be I/N with 0 <= I < N\n";
        return 2;
      }
      const exc::sim::SweepSpec spec = exc::sim::load_sweep_spec(sweep_spec);
      if (spec.run != exc::sim::SweepRun::closed_loop) {
        std::cerr << "excavator-sim sweep: " << sweep_spec << ": an open-loop sweep runs in excavator-bench (its step map)\n";
        return 2;
      }
      if (sweep_check) {
        std::cout << sweep_spec << ": " << spec.total_cases() << " cases\n";
        return 0;
      }
      if (sweep_out.empty())
        sweep_out = (fs::path("out/sweep") / ("shard-" + std::to_string(shard) + "-of-" + std::to_string(shards) + ".jsonl")).string();
      const int n = exc::sim::run_sweep_shard(spec, shard, shards, sweep_out, !sweep_quiet);
      std::cout << "sweep shard " << shard << "/" << shards << ": " << n << " cases -> " << sweep_out << "\n";
      return 0;
    } catch (const std::exception& e) {
      std::cerr << "excavator-sim: " << e.what() << "\n";
      return 2;
    }
  }

  if (robust->parsed()) {
    try {
      exc::sim::SweepSpec spec = exc::sim::load_sweep_spec(robust_spec, [&](const std::vector<std::string>& listed) {
        return robust_scene.empty() ? listed : std::vector<std::string>{robust_scene};
      });
      exc::sim::RunOptions options;
      options.controllers = robust_controllers.empty() ? spec.controllers : robust_controllers;
      options.duration_override = robust_duration;
      options.progress = !robust_quiet;
      const exc::sim::SceneBundle& bundle = spec.sources.front()->nominal;
      // Both output files are opened before the variants run: a path that cannot be written costs no run time.
      if (robust_out.empty()) robust_out = (fs::path("out") / (bundle.name + "-robustness")).string();
      fs::create_directories(robust_out);
      const fs::path table = fs::path(robust_out) / "robustness.json";
      std::ofstream table_file = exc::output::open_file(table);
      std::ofstream json_file;
      if (!robust_json.empty()) json_file = exc::output::open_file(robust_json);
      const auto rows = exc::sim::run_robustness(spec, options);
      exc::sim::print_robustness(rows, std::cout);
      const std::string text = exc::sim::robustness_json(rows).dump(2) + "\n";
      table_file << text;
      exc::output::finish_file(table_file, table);
      if (!robust_json.empty()) {
        json_file << text;
        exc::output::finish_file(json_file, robust_json);
      }
      if (!robust_no_plots) {
        const int rc = exc::sim::plot_robustness(table, robust_out);
        if (rc != 0) {
          std::cerr << "excavator-sim: the robustness chart failed (exit " << rc << "); the table is in " << table.string()
                    << "\n";
          return 1;
        }
        std::cout << "chart: " << (fs::path(robust_out) / "robustness.png").string() << "\n";
      }
      // A variant may fail (that is a finding, printed in the table); the program itself succeeded.
      return 0;
    } catch (const std::exception& e) {
      std::cerr << "excavator-sim: " << e.what() << "\n";
      return 2;
    }
  }

  if (paper->parsed()) {
    try {
      // The three scenes, each into its own folder with its own report, then the paper's page.
      const fs::path out = paper_out;
      fs::create_directories(out);
      exc::sim::SceneJob free_job, dig_job, hydraulic_job;
      free_job.scene_path = paper_free;
      free_job.out_dir = out / "free_motion";
      dig_job.scene_path = paper_dig;
      dig_job.out_dir = out / "dig";
      hydraulic_job.scene_path = paper_hydraulic;
      hydraulic_job.out_dir = out / "hydraulic_dig";
      for (exc::sim::SceneJob* job : {&free_job, &dig_job, &hydraulic_job}) {
        job->progress = !paper_quiet;
        job->duration = paper_duration;
        job->log_every = paper_log_every;
      }
      // All three logs are sized before the first run: a disk too small for them refuses the job at once.
      const exc::sim::SceneJobPlan free_plan = exc::sim::plan_scene_job(free_job);
      const exc::sim::SceneJobPlan dig_plan = exc::sim::plan_scene_job(dig_job);
      const exc::sim::SceneJobPlan hydraulic_plan = exc::sim::plan_scene_job(hydraulic_job);
      exc::sim::check_log_room({&free_plan, &dig_plan, &hydraulic_plan});
      exc::sim::catch_run_interrupt();
      // Interrupted, the scenes after the one that was running do not run, and there is no paper page.
      const exc::sim::SceneJobResult free_result = exc::sim::run_scene_job(free_plan);
      if (free_result.summary.interrupted) return free_result.exit_code;
      const exc::sim::SceneJobResult dig_result = exc::sim::run_scene_job(dig_plan);
      if (dig_result.summary.interrupted) return dig_result.exit_code;
      const exc::sim::SceneJobResult hydraulic_result = exc::sim::run_scene_job(hydraulic_plan);
      if (hydraulic_result.summary.interrupted) return hydraulic_result.exit_code;
      if (!exc::sim::write_paper_report(out, free_result, dig_result, hydraulic_result)) {
        std::cerr << "excavator-sim: cannot write " << (out / "report.md").string() << "\n";
        return 1;
      }
      std::cout << "paper figures: " << (out / "report.md").string() << "\n";
      return std::max({free_result.exit_code, dig_result.exit_code, hydraulic_result.exit_code});
    } catch (const std::exception& e) {
      std::cerr << "excavator-sim: " << e.what() << "\n";
      return 2;
    }
  }

  try {
    exc::sim::SceneJob job;
    job.scene_path = scene_path;
    job.out_dir = out_dir;
    job.controllers = controllers;
    job.lcm_url = lcm_url;
    job.json_path = json_path;
    job.duration = duration;
    job.log_every = log_every;
    job.report = !no_report;
    job.progress = !quiet;
    job.firmware_target = firmware_target;
    const exc::sim::SceneJobPlan plan = exc::sim::plan_scene_job(job);
    exc::sim::check_log_room({&plan});
    exc::sim::catch_run_interrupt();
    return exc::sim::run_scene_job(plan).exit_code;
  } catch (const std::exception& e) {
    std::cerr << "excavator-sim: " << e.what() << "\n";
    return 2;
  }
}
