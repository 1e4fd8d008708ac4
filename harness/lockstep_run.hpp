#pragma once
// The one way to run a scene: firmware and plant in one process over the in-memory CAN bus, stepping
// in SYNC lockstep (firmware SYNC -> plant step + sensor frames -> firmware control + commands), the
// same frames as on a real bus. excavator-sim (main job, robustness), excavator-bench (fidelity and
// controller maps) and the sweeps all call run_lockstep; its RunRecord is what the JSON summary, the
// report and the charts read. The bus is stamped with simulated time, so a run is deterministic.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/firmware_settings.hpp"
#include "app/float_environment.hpp"
#include "app/run_phases.hpp"
#include "app/settings_blob.hpp"
#include "harness/fault_injector.hpp"
#include "harness/scene_source.hpp"
#include "harness/stop_judge.hpp"
#include "harness/target_figures.hpp"
#include "control/controller_config.hpp"
#include "sim_plant/scene.hpp"

namespace exc::telemetry {
class LcmOutput;
}
namespace exc::plant {
class Plant;
class PlantNode;
}
namespace exc::app {
class FirmwareNode;
}

namespace exc::sim {

struct Timing {
  double median_us = 0, p99_us = 0, max_us = 0;
  std::uint64_t count = 0;
};

// The control step's and the plant step's timing over one stretch of a run: a cycle's cost must not
// depend on the run's history (docs/floating-point.md), so the first and the last simulated second
// of a long run are compared. From the counters' histograms: each figure is its bucket's upper edge
// (at most 5 % high), the max too.
struct TimingWindow {
  double start = 0, end = 0;  // s of the run
  Timing control_step, plant_step;
};

// One work cycle of a run (a task done once has one): while tracking, true q_a against q_d.
struct CycleRecord {
  double start = 0, end = 0;        // s of the run, first and last tracked cycle
  std::uint64_t samples = 0;
  double rms_error[4] = {0, 0, 0, 0};
  double max_error[4] = {0, 0, 0, 0};
  double peak_soil_force = 0;       // N
  double theta_hat[6] = {0, 0, 0, 0, 0, 0};  // the soil estimates at the cycle's end
};

// The errors of one phase of a run (tracking, settle, hold, stop) and the holding tolerance the
// verdict holds a hold to: the one phase split of every summary (app/run_phases.hpp); here from the
// plant's truth.
using app::PhaseErrors;
using app::kHoldingTolerance;
using app::kHoldSettleLimit;
using app::kHoldSettleDwell;

// One closed-loop run, as every report reads it.
struct RunRecord {
  std::string controller;
  bool ok = true;
  std::string failure;                // plant or firmware failure message ("" when ok)
  double simulated_seconds = 0;
  double wall_seconds = 0;
  double cpu_seconds = 0;             // thread CPU time of the stepping loop
  std::uint64_t tracking_samples = 0; // cycles in track mode (the error figures' sample count)
  double rms_error[4] = {0, 0, 0, 0};  // while tracking: true q_a against q_d; rad (swing), m (cylinders)
  double max_error[4] = {0, 0, 0, 0};
  // The same as the firmware measures it (sensed q_a, after CAN scaling): what excavator-firmware
  // reports in a two-process run, and equal to it bit for bit (SYNC lockstep).
  double measured_rms_error[4] = {0, 0, 0, 0};
  double measured_max_error[4] = {0, 0, 0, 0};
  // Every phase (app/run_phases.hpp) on the plant's truth: tracking (the figures above, with each
  // max's time and the excursions), settle, hold, stop.
  PhaseErrors tracking, settle, hold, stop;
  double theta_hat[6] = {0, 0, 0, 0, 0, 0};
  double theta_true[6] = {0, 0, 0, 0, 0, 0};
  double peak_soil_force = 0;         // N, |F_soil| maximum
  int reanchor_count = 0;
  Timing control_step;                // estimate + trajectory + control law
  TimingWindow first_second, last_second;  // of the run (the whole run when it is shorter)
  Timing firmware_cycle;              // read + control + write + telemetry encode
  std::uint64_t heap_allocations_in_loop = 0;
  std::uint64_t safe_stops = 0;
  std::uint64_t rx_rejected = 0;      // CAN frames rejected by either end
  // The telemetry path (zero everywhere without telemetry): messages the loop enqueued, handed to LCM,
  // refused because the ring was full (never with the blocking publisher the harness uses).
  std::uint64_t telemetry_enqueued = 0, telemetry_published = 0, telemetry_dropped = 0;
  std::size_t telemetry_ring_high_water = 0;
  std::uint32_t telemetry_per_cycle_every = 1;  // the per-cycle channels recorded every Nth cycle (LockstepOptions::log_every)
  std::vector<CycleRecord> cycles;    // per work cycle of the task
  double first_safe_stop_time = -1;   // s of the first safe state (-1: none)
  double first_fault_detected_time = -1;  // s its fault was detected (FirmwareNode::fault_detected_time)
  // s, the plant's truth: a stuck spool's onset of disagreement before that detection
  // (harness/spool_disagreement.hpp; -1: none, or no stop)
  double spool_disagreement_onset = -1;
  int first_fault_code = 0;               // safety::FirmwareFault of the first safe state
  // Judged by the machine (docs/safety.md), from the plant's truth: the first time after which every
  // cylinder stays under 1 mm/s and the swing under 1 mrad/s to the run's end (-1: it never does,
  // i.e. it still moves at the end), and whether the firmware sent the emergency stop.
  double machine_at_rest_time = -1;
  bool estop = false;
  // The hydraulic machine (zeros for force-commanded fidelities), from the plant's true circuit and
  // the firmware's valve stage.
  bool hydraulic = false;
  double peak_pressure = 0;           // Pa, the highest chamber pressure of the run
  double min_pressure = 0;            // Pa, the lowest (never below the vapour floor: the plant checks)
  double flow_saturated_seconds = 0;  // s the pumps' demand was above their flow (every function slowed)
  double relief_seconds = 0;          // s with a relief valve open
  double cavitation_seconds = 0;      // s with a chamber held at the vapour floor by the make-up
  std::uint64_t pump_limited_cycles = 0;  // firmware cycles whose openings asked more than the pumps give
  bool task_finished = false;         // the task ran to its end (then the machine held its final pose)
  double task_finish_time = 0;        // s
  // Ended early by LockstepOptions::interrupt (a person's Ctrl-C): not ok, its figures those of the
  // cycles that ran.
  bool interrupted = false;
  // A run on an emulated target (LockstepOptions::firmware_target): the image's own figures. Its
  // heap_allocations_in_loop are then the image's allocator calls after start-up, and the host's
  // timing figures above are left empty (count 0): the host did not run the firmware.
  std::optional<TargetFigures> target;
  // A run with a fault whose stop was taken: the stop judged on the plant's truth against R1-R3
  // (harness/stop_judge.hpp; docs/safety.md, "The stop requirement").
  std::optional<StopJudgement> stop_judgement;
};

struct LockstepOptions {
  std::string controller = "adaptive";  // the law's registered name (control/controller_registry.hpp)
  double duration = 0;  // s; 0: the scene's
  // Telemetry into this provider (null: none), channels suffixed "/<controller>".
  std::shared_ptr<telemetry::LcmOutput> telemetry;
  // Record the per-cycle channels (EXC_STATE, EXC_COMMAND, EXC_CONTROLLER) every Nth cycle only, from
  // the first (TelemetryConfig::per_cycle_every): a long run's log at a fraction of the size.
  std::uint32_t log_every = 1;
  bool progress = false;            // one line per tenth of the run on stderr
  bool stop_at_safe_state = false;  // end the run at the firmware's first safe stop (maps, sweeps)
  // s after the firmware's first safe stop a run may go on past the scene's end while the machine
  // still moves, so that its time to rest is seen, not cut off (the fault campaign); it ends once
  // the machine has been at rest kRestSettle. 0: the scene's duration, always.
  double rest_horizon = 0;
  FaultSchedule fault;
  // Operator commands, in time order; and whether the firmware waits for a start before tracking.
  std::vector<SupervisorFrameAt> supervisor;
  bool wait_for_start = false;
  // Called after every cycle (e.g. to sample the tip for a chart). Must not allocate in the loop.
  std::function<void(std::int64_t cycle, const plant::Plant&, const app::FirmwareNode&)> observer;
  // Called after every cycle with both nodes (e.g. to scan their state). Must not allocate in the loop.
  std::function<void(std::int64_t cycle, const plant::PlantNode&, const app::FirmwareNode&)> node_observer;
  // The run's floating-point mode (the thread's own is restored after it): flush_subnormals, the
  // loop's; ieee only to measure what it saves (docs/floating-point.md).
  app::FloatMode float_mode = app::FloatMode::flush_subnormals;
  // Where the firmware runs: "" in this process, "cortex-m7" its image on the emulated Cortex-M7
  // (processor in the loop, docs/target.md; firmware_image: the ELF, empty for this build's). The
  // observers take the in-process node and are refused with a target.
  std::string firmware_target;
  std::string firmware_image;
  // Non-zero (a signal handler sets it): the run ends at the next cycle boundary, interrupted.
  const std::atomic<int>* interrupt = nullptr;
};

// The cycles a run of `scene` lasts: `duration` s, or the scene's own duration when it is 0.
std::int64_t lockstep_cycles(const plant::Scene& scene, double duration);

// Runs the plant's scene against the firmware's settings (which may differ on purpose: a wrong
// model, other gains). The plant starts from the scene's initial state.
RunRecord run_lockstep(const plant::Scene& scene, const app::FirmwareSettings& firmware, const LockstepOptions& options);
// What the firmware's node of that run is built from (options.controller its law, options.wait_for_start,
// the scene's true soil as theta_true), as the settings blob carries it to the firmware's image.
app::FirmwareImageSettings lockstep_image_settings(const plant::Scene& scene, const app::FirmwareSettings& firmware,
                                                   const LockstepOptions& options);
// The same run from those (decoded from a blob, say): the node is built from them alone, so
// options.controller and options.wait_for_start are theirs to say; the run lasts the scene's duration
// (or options.duration) in the plant's cycles, as above.
RunRecord run_lockstep(const plant::Scene& scene, const app::FirmwareImageSettings& firmware, const LockstepOptions& options);

}  // namespace exc::sim
