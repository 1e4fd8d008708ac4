#pragma once
// The runs excavator-bench is made of. Two kinds:
//  - open loop: the plant driven by a fixed effort profile (the task's inverse-dynamics feed-forward,
//    held over 10 ms), so every integrator, formulation and step size (and MuJoCo) integrates the
//    very same input from the very same state; used by the work-precision chart, the step-size
//    stability map and the MuJoCo comparison;
//  - closed loop: firmware and plant over the in-memory CAN bus in SYNC lockstep (as excavator-sim
//    runs them), used by the fidelity chart and the controller stability maps.
#include <string>
#include <vector>

#include "app/firmware_settings.hpp"
#include "control/controller_config.hpp"
#include "control/task/task.hpp"
#include "harness/scene_source.hpp"
#include "sim_plant/scene.hpp"

namespace exc::bench {

// A scene prepared for benchmarking: its plant sections, task and controller, and the window of the
// task that the open-loop runs cover.
struct BenchScene {
  std::string name;
  plant::Scene scene;
  control::Task task;
  control::ControllerConfig controller;
  double start = 0;    // s of the task where the open-loop window starts
  double horizon = 1;  // s simulated in open loop
};

BenchScene load_bench_scene(const std::string& path, double start, double horizon);
// The same from a scene already read.
BenchScene bench_scene(const sim::SceneBundle& scene, double start, double horizon);

// Efforts tau_a held over kProfileHold: the inverse dynamics of the closed chain (eq. 16b) along the
// task's desired trajectory, no soil. Every step size of the charts divides kProfileHold.
constexpr double kProfileHold = 0.01;
struct EffortProfile {
  std::vector<Vec4> tau;  // one per hold interval from the window start
  Vec4 q_a0 = Vec4::Zero(), qd_a0 = Vec4::Zero();
};
// speed > 1 runs the task faster (positions along the same path, velocities x speed, accelerations
// x speed^2): the joint-speed axis of the stability map.
EffortProfile effort_profile(const BenchScene& s, double speed = 1.0);

struct OpenLoopSettings {
  plant::IntegratorSettings integrator;
  double constraint_tolerance = 1e-2;  // m: wide, so the chart shows the residual growing
  // false (work-precision chart): the energy-balance check is widened as well, because the energy
  // drift is one of the chart's measured errors; the stability maps keep the plant's own settings.
  bool plant_energy_check = true;
};

struct OpenLoopResult {
  bool ok = true;
  std::string failure;            // the plant's own check that stopped the run
  double simulated = 0;           // s reached
  double cpu_seconds = 0;         // thread CPU time of the stepping loop
  std::vector<Vec3> tip;          // tip_world at every kProfileHold (first: the initial state)
  std::vector<Vec4> effort;
  double max_constraint_residual = 0;  // m
  double max_energy_error = 0;         // J
  double step_median_us = 0;      // one plant step (one cycle)
  std::vector<Vec12> q, qd;       // the tree state at every kProfileHold (for the peer's inverse)
};

// Plant cycle: the step itself above 1 ms, else 1 ms with substeps (both divide kProfileHold).
OpenLoopResult run_open_loop(const BenchScene& s, const EffortProfile& profile, const OpenLoopSettings& settings,
                             bool record_states = false);

// RMS over samples of |a - b| (only the common prefix; +inf when one of them is empty).
double rms_distance(const std::vector<Vec3>& a, const std::vector<Vec3>& b);

struct ClosedLoopVariant {
  std::string controller = "adaptive";  // the law's registered name
  std::string fidelity = "ideal";  // actuators.fidelity
  bool soil = true;                 // false: soil removed from the scene
  bool dry_friction_and_leakage = true;  // false: the hydraulic machine with viscous friction only (the old plant)
  bool massless_cylinders = false;  // cylinder bodies at 1e-3 of their mass (earlier works' model)
  double duration = 0;              // s; 0: the scene's
};

struct ClosedLoopResult {
  bool ok = true;
  std::string failure;
  double simulated = 0, cpu_seconds = 0;
  std::vector<Vec3> tip;          // every kProfileHold
  std::vector<Vec4> effort;       // applied efforts, every kProfileHold
  double tracking_rms[4] = {0, 0, 0, 0};
  double tracking_max = 0;        // worst joint, m or rad
};

// The firmware's settings for the machine it drives: the valve interface for a fidelity that takes
// valve commands (hydraulic), efforts otherwise, with the fidelity's effort lag compensated (limited's;
// none for ideal ones).
void configure_for_fidelity(control::ControllerConfig& c, const plant::ActuatorParameters& actuators, const Machine& nominal);

// The firmware's settings for a closed-loop run of `scene` (the plant's side of s, changed): the
// bench scene's task and controller set for the scene's actuators, its model the full machine.
app::FirmwareSettings bench_firmware(const BenchScene& s, const plant::Scene& scene);

ClosedLoopResult run_closed_loop(const BenchScene& s, const ClosedLoopVariant& v);

// Thread CPU time in seconds (not disturbed by other processes on the machine).
double thread_cpu_seconds();

}  // namespace exc::bench
