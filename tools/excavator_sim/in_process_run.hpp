#pragma once
// The main job's engine: firmware and plant in one process over the in-memory CAN bus, stepping in
// SYNC lockstep (firmware SYNC -> plant step + sensor frames -> firmware control + commands), one
// run per controller, all into one LCM log with a channel suffix per controller.
#include <cstdint>
#include <string>
#include <vector>

#include "control/controller_config.hpp"
#include "control/task.hpp"
#include "sim_plant/scene.hpp"

namespace exc::sim {

struct SceneBundle {
  std::string name;
  plant::Scene scene;
  control::Task task;
  control::ControllerConfig controller;
};

// Loads the plant's sections, the task and the controller section of one scene file (all
// validated; errors name the file and the field).
SceneBundle load_scene_bundle(const std::string& path);

struct RunOptions {
  std::string scene_path;
  std::vector<std::string> controllers;  // pid, adaptive, slotine_li
  double duration_override = 0;          // s; 0: the scene's duration
  std::string lcm_url;                   // empty: no telemetry
  bool progress = true;
  // Robustness: the firmware's model has every link's mass and inertia scaled by this factor while
  // the plant keeps the true machine (1: exact model).
  double controller_mass_scale = 1.0;
};

struct Timing {
  double median_us = 0, p99_us = 0, max_us = 0;
  std::uint64_t count = 0;
};

struct RunResult {
  std::string controller;
  bool ok = true;
  std::string failure;                // plant or firmware failure message ("" when ok)
  double simulated_seconds = 0;
  double wall_seconds = 0;
  double rms_error[4] = {0, 0, 0, 0};  // while tracking; rad (swing), m (cylinders)
  double max_error[4] = {0, 0, 0, 0};
  // The same as the firmware measures it (sensed q_a, after CAN scaling): what excavator-firmware
  // reports in a two-process run, and equal to it bit for bit (SYNC lockstep).
  double measured_rms_error[4] = {0, 0, 0, 0};
  double measured_max_error[4] = {0, 0, 0, 0};
  double theta_hat[6] = {0, 0, 0, 0, 0, 0};
  double theta_true[6] = {0, 0, 0, 0, 0, 0};
  double peak_soil_force = 0;         // N, |F_soil| maximum
  int reanchor_count = 0;
  Timing control_step;                // estimate + trajectory + control law
  Timing firmware_cycle;              // read + control + write + telemetry encode
  std::uint64_t heap_allocations_in_loop = 0;
  std::uint64_t safe_stops = 0;
  std::uint64_t rx_rejected = 0;      // CAN frames rejected by either end
};

struct Summary {
  std::string scene;
  // What ran, as a person reads it: the plant's actuators and integrator, the firmware's lag compensation.
  std::string setup;
  std::vector<RunResult> runs;
  bool all_ok = true;
};

Summary run_all(const SceneBundle& bundle, const RunOptions& options);

}  // namespace exc::sim
