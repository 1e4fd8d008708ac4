#pragma once
// One scene as the main job runs it: the runs of its controllers into one LCM log, the summary on
// stdout and as JSON, the effective configuration (<out>/effective.yaml) and the report page (CSVs,
// figures, report.md) of excavator-log. Before the runs the log's expected size is stated, and a
// file system that cannot hold it refuses the job.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "in_process_run.hpp"

namespace exc::sim {

struct SceneJob {
  std::string scene_path;
  std::filesystem::path out_dir;         // empty: out/<scene name>
  // empty: the scene's controller.type, else pid and adaptive (and flow on a valve-commanded machine whose task holds the swing)
  std::vector<std::string> controllers;
  std::string lcm_url;                   // empty: file://<out>/run.lcm?mode=w
  std::string json_path;                 // also write the summary here (optional)
  double duration = 0;                   // s; 0: the scene's
  std::uint32_t log_every = 1;           // the per-cycle channels every Nth cycle (--log-every)
  bool report = true;
  bool progress = true;
  std::string firmware_target;           // --firmware-target: "" in this process, "cortex-m7" on the emulated target
};

// A scene job loaded and sized, before anything is run or written.
struct SceneJobPlan {
  SceneJob job;
  SceneBundle bundle;
  RunOptions options;
  std::filesystem::path out_dir;
  std::filesystem::path log;      // the log file the telemetry writes; empty for a provider with no file (udpm://)
  std::int64_t cycles = 0;        // per controller
  std::uint64_t log_bytes = 0;    // expected size of the log (harness/log_volume.hpp), every controller
  std::uint64_t per_cycle_bytes = 0;  // of one controller's recorded cycle (the controllers' mean)
};

struct SceneJobResult {
  Summary summary;
  std::filesystem::path out_dir;
  int exit_code = 0;  // 0 every run ok and the report written; 1 a run or the report failed
};

// Loads the scene (errors throw, naming file and field), chooses the controllers and sizes the log.
SceneJobPlan plan_scene_job(const SceneJob& job);
// States each plan's log and its expected size on stderr, a line each, and throws std::runtime_error
// when a file system cannot hold the logs that go to it (its free space from statvfs; a log that
// exists is overwritten, so its size counts as free), naming the logs, both sizes and what to change.
void check_log_room(const std::vector<const SceneJobPlan*>& plans);
// Runs, prints, writes.
SceneJobResult run_scene_job(const SceneJobPlan& plan);
// plan_scene_job, check_log_room, run_scene_job.
SceneJobResult run_scene_job(const SceneJob& job);

}  // namespace exc::sim
