// The lockstep run, top to bottom as a cycle reads: the rig (harness/lockstep_rig.hpp) steps plant
// and firmware, the recorder (run_recorder.hpp) and the timing windows (timing_windows.hpp) take
// what each cycle shows, the verdict says whether the run did what it was asked.
#include "harness/lockstep_run.hpp"

#include <time.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <stdexcept>

#include "app/allocation_counter.hpp"
#include "app/firmware_node.hpp"
#include "harness/lockstep_rig.hpp"
#include "harness/run_recorder.hpp"
#include "harness/timing_windows.hpp"

namespace exc::sim {
namespace {

Vec6 theta_of(const plant::SoilParameters& s) {
  Vec6 t;
  t << s.mass[0], s.damping[0], s.stiffness[0], s.mass[1], s.damping[1], s.stiffness[1];
  return t;
}

double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// One line per tenth of the run on stderr: redrawn in place on a terminal, a line each in a log.
class ProgressLine {
 public:
  ProgressLine(bool on, const std::string& law, std::int64_t cycles, double duration)
      : on_(on), interactive_(isatty(STDERR_FILENO) != 0), law_(law), every_(std::max<std::int64_t>(1, cycles / 10)),
        duration_(duration) {}
  void update(std::int64_t cycles_run, double t) const {
    if (!on_ || cycles_run % every_ != 0) return;
    std::fprintf(stderr, interactive_ ? "\r  %-10s %5.1f / %.1f s simulated" : "  %-10s %5.1f / %.1f s simulated\n",
                 law_.c_str(), t, duration_);
    std::fflush(stderr);
  }
  ~ProgressLine() {
    if (on_ && interactive_) std::fprintf(stderr, "\n");
  }

 private:
  bool on_, interactive_;
  std::string law_;
  std::int64_t every_;
  double duration_;
};

// Whether the run did what it was asked, in the order a person would want to know it.
void set_verdict(RunRecord& r, const app::RunSummaryRecord& outcome, const char* plant_failure, double planned_seconds) {
  const char* const mode = safety::to_string(static_cast<safety::Mode>(outcome.mode));
  r.ok = false;
  if (r.interrupted) {
    char text[96];
    std::snprintf(text, sizeof text, "interrupted (SIGINT) at %.3f s of %.3f s", r.simulated_seconds, planned_seconds);
    r.failure = text;
  } else if (plant_failure != nullptr) {
    r.failure = std::string("plant stopped: ") + plant_failure;
  } else if (r.safe_stops > 0) {
    r.failure = "the firmware went to its safe state " + std::to_string(r.safe_stops) + " time(s), the last for " +
                outcome.last_fault_text + " (mode " + mode + " at the end)";
  } else if (r.tracking_samples == 0) {
    r.failure = std::string("the firmware never tracked (mode ") + mode + ")";
  } else {
    // The hold is part of the task: a machine told to hold still that moves past the holding
    // tolerance failed it, however well it tracked.
    r.failure = app::hold_failure(r.hold);
    r.ok = r.failure.empty();
  }
}

}  // namespace


std::int64_t lockstep_cycles(const plant::Scene& scene, double duration) {
  return static_cast<std::int64_t>(std::llround((duration > 0 ? duration : scene.duration) / scene.cycle));
}

app::FirmwareImageSettings lockstep_image_settings(const plant::Scene& scene, const app::FirmwareSettings& firmware,
                                                   const LockstepOptions& options) {
  app::FirmwareNodeConfig fc;
  fc.controller = firmware.controller;
  fc.controller.law = options.controller;
  fc.site_map = firmware.terrain;
  fc.theta_known = true;  // simulation: the true soil goes into telemetry and the Lyapunov value
  fc.theta_true = theta_of(scene.soil);
  fc.wait_for_start = options.wait_for_start;
  return app::image_settings(firmware, fc, options.duration > 0 ? options.duration : scene.duration);
}

RunRecord run_lockstep(const plant::Scene& scene, const app::FirmwareSettings& firmware, const LockstepOptions& options) {
  return run_lockstep(scene, lockstep_image_settings(scene, firmware, options), options);
}

RunRecord run_lockstep(const plant::Scene& scene, const app::FirmwareImageSettings& firmware, const LockstepOptions& options) {
  if (const std::string why = fault_misfit(options.fault.kind, scene); !why.empty()) throw std::invalid_argument("fault: " + why);
  // This thread runs the loop and starts the telemetry thread: subnormals flushed from here on, the
  // caller's mode back at the end (docs/floating-point.md).
  const app::LoopFloatModeScope float_mode(options.float_mode);
  RunRecord result;
  result.controller = firmware.node.controller.law;
  if (options.telemetry) result.telemetry_per_cycle_every = options.log_every;
  LockstepRig rig(scene, firmware, options);
  const std::int64_t cycles = lockstep_cycles(scene, options.duration);
  RunRecorder recorder(scene, firmware.task.cycle_starts, options.fault, rig.machine(), firmware.node.controller.supervisor.spool_monitor);
  TimingWindows timing(cycles, scene.cycle);
  const auto control_timing = [&rig] { return rig.host_node() != nullptr ? &rig.host_node()->control_timing() : nullptr; };
  // A stopped run may go on past the scene's end, to see the machine come to rest (rest_horizon).
  const std::int64_t horizon = options.rest_horizon > 0 ? static_cast<std::int64_t>(std::ceil(options.rest_horizon / scene.cycle)) : 0;
  const auto wall_start = std::chrono::steady_clock::now();
  const double cpu_start = thread_cpu_seconds();
  std::int64_t cycles_run = 0;
  std::uint64_t allocations = 0;
  {
    const ProgressLine progress(options.progress, result.controller, cycles, options.duration > 0 ? options.duration : scene.duration);
    // Counted from the first cycle on: everything before is start-up. The telemetry thread's own
    // allocations (LCM) are on another thread and not counted.
    app::AllocationCounter counter;
    for (std::int64_t k = 0; k < cycles + horizon; ++k) {
      const double now = static_cast<double>(k) * scene.cycle;
      if (k >= cycles && !recorder.runs_on(now, options.rest_horizon)) break;
      timing.before_cycle(k, control_timing(), rig.plant_node().step_timing());
      rig.step(k, now);
      cycles_run = k + 1;
      timing.after_cycle(cycles_run, control_timing(), rig.plant_node().step_timing());
      recorder.record(rig.machine(), rig.firmware().status());
      if (options.observer) options.observer(k, rig.machine(), *rig.host_node());
      if (options.node_observer) options.node_observer(k, rig.plant_node(), *rig.host_node());
      if (rig.plant_node().failed() || (options.stop_at_safe_state && rig.firmware().status().safe_stops > 0)) break;
      if (options.interrupt != nullptr && options.interrupt->load(std::memory_order_relaxed) != 0) {
        result.interrupted = true;
        break;
      }
      progress.update(cycles_run, rig.machine().state().time);
    }
    allocations = counter.count();
  }
  result.cpu_seconds = thread_cpu_seconds() - cpu_start;
  const app::RunSummaryRecord outcome = rig.finish(result);
  result.wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  recorder.finish(result);
  timing.finish(result, cycles_run, control_timing(), rig.plant_node().step_timing());
  const plant::PlantState& end = rig.machine().state();
  result.simulated_seconds = end.time;
  result.reanchor_count = end.reanchor_count;
  const Vec6 truth = theta_of(scene.soil);
  for (int i = 0; i < 6; ++i) {
    result.theta_hat[i] = rig.firmware().status().theta_hat[i];
    result.theta_true[i] = truth[i];
  }
  for (int j = 0; j < 4; ++j) {
    result.measured_rms_error[j] = outcome.measured_rms[j];
    result.measured_max_error[j] = outcome.measured_max[j];
  }
  result.estop = outcome.emergency_sent;
  result.heap_allocations_in_loop = result.target ? result.target->heap_calls_after_start_up : allocations;
  result.safe_stops = rig.firmware().status().safe_stops;
  if (result.hydraulic) {
    const double step = scene.integrator.step;
    result.flow_saturated_seconds = static_cast<double>(end.hydraulics.saturated_substeps) * step;
    result.relief_seconds = static_cast<double>(end.hydraulics.relief_substeps) * step;
    result.cavitation_seconds = static_cast<double>(end.hydraulics.cavitation_substeps) * step;
    result.pump_limited_cycles = outcome.pump_limited_cycles;
  }
  result.task_finished = outcome.trajectory_finished;
  result.task_finish_time = outcome.finish_time;
  set_verdict(result, outcome, rig.plant_node().failed() ? rig.machine().status().text() : nullptr,
              static_cast<double>(cycles) * scene.cycle);
  return result;
}

}  // namespace exc::sim
