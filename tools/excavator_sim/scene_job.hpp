#pragma once
// One scene as the main job runs it: the runs of its controllers into one LCM log, the summary on
// stdout and as JSON, the effective configuration (<out>/effective.yaml) and the report page (CSVs,
// figures, report.md) of excavator-log.
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
  bool report = true;
  bool progress = true;
};

struct SceneJobResult {
  Summary summary;
  std::filesystem::path out_dir;
  int exit_code = 0;  // 0 every run ok and the report written; 1 a run or the report failed
};

// Loads (errors throw, naming file and field), runs, prints, writes.
SceneJobResult run_scene_job(const SceneJob& job);

}  // namespace exc::sim
