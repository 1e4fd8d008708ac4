#pragma once
// The main job's runs: one lockstep run per controller (harness/lockstep_run.hpp), all into one LCM
// log with a channel suffix per controller.
#include <cstdint>
#include <string>
#include <vector>

#include "harness/lockstep_run.hpp"

namespace exc::sim {

using RunResult = RunRecord;

struct RunOptions {
  std::string scene_path;
  std::vector<std::string> controllers;  // pid, adaptive, slotine_li
  double duration_override = 0;          // s; 0: the scene's duration
  std::string lcm_url;                   // empty: no telemetry
  std::uint32_t log_every = 1;           // the per-cycle channels every Nth cycle (LockstepOptions::log_every)
  bool progress = true;
  std::string firmware_target;           // "": in this process; "cortex-m7": on the emulated target (LockstepOptions)
  const std::atomic<int>* interrupt = nullptr;  // LockstepOptions::interrupt; the controllers after it do not run
};

struct Summary {
  std::string scene;
  // What ran, as a person reads it: the plant's actuators and integrator, the firmware's lag compensation.
  std::string setup;
  std::vector<RunRecord> runs;
  bool all_ok = true;
  bool interrupted = false;  // a run ended by LockstepOptions::interrupt; the controllers after it not run
};

// The run's setup as a person reads it: actuators (and their lag), the firmware's compensation of
// it, the integrator.
std::string describe_setup(const SceneBundle& bundle);

// Each name a controller kind, none twice (their runs share one log, a channel per controller):
// std::invalid_argument naming --controller otherwise.
void check_controller_names(const std::vector<std::string>& names);

Summary run_all(const SceneBundle& bundle, const RunOptions& options);

}  // namespace exc::sim
