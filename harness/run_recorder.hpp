#pragma once
// What a lockstep run records after each cycle, from the plant's truth and the firmware's status
// (allocation-free in the loop): the errors per phase and per work cycle, the peaks of soil force and
// chamber pressure, when the machine last moved, the first safe stop and, for a run with a fault,
// the onset of a stuck spool's disagreement and the stop's judge. After the run it fills its part of the RunRecord.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "app/run_phases.hpp"
#include "app/pil_records.hpp"
#include "harness/fault_injector.hpp"
#include "harness/lockstep_run.hpp"
#include "harness/spool_disagreement.hpp"
#include "harness/stop_judge.hpp"
#include "sim_plant/plant.hpp"

namespace exc::sim {

class RunRecorder {
 public:
  // `cycle_starts`: the task's work cycles' start times (empty: one); `fault`: the run's (its judge
  // records from its start); `plant`: the machine before the first cycle.
  // `spool_limits`: the spool monitor's, by which a stuck spool's onset of disagreement is judged.
  RunRecorder(const plant::Scene& scene, const std::vector<double>& cycle_starts, const FaultSchedule& fault,
              const plant::Plant& plant, const safety::SpoolMonitorSettings& spool_limits);

  // After each cycle: the plant's truth and the firmware's status.
  void record(const plant::Plant& plant, const app::CycleStatus& st);
  // Past the scene's end: whether a stopped run goes on at `now` to see its machine come to rest
  // (at rest for kRestSettle and, for a judged stop, its drift fit covered), at most rest_horizon s
  // after its first safe stop.
  bool runs_on(double now, double rest_horizon) const;

  // The figures recorded into r: errors per phase and work cycle, peaks, the machine at rest, the
  // first safe stop and its judgement.
  void finish(RunRecord& r) const;

 private:
  const plant::Scene& scene_;
  const std::vector<double>& starts_;
  const FaultSchedule fault_;
  const bool hydraulic_;
  app::RunPhases phases_;  // tracking, settle, hold, stop: on the plant's truth
  // Per work cycle: sized here, so the loop allocates nothing.
  std::vector<CycleRecord> cycles_;
  std::vector<std::array<double, 4>> cycle_sum_sq_;
  double peak_soil_force_ = 0, peak_pressure_ = 0, min_pressure_ = 0;
  // The machine's truth: the last cycle any function moved faster than "at rest" (docs/safety.md).
  double last_moving_ = -1;
  bool moving_now_ = false;
  double first_safe_stop_time_ = -1, first_fault_detected_time_ = -1;
  int first_fault_code_ = 0;
  // A stuck spool's onset of disagreement, up to the first detection (R1 counts from it).
  SpoolDisagreement disagreement_;
  // The stop's judge records the plant's truth from the fault's start (its ring reserved here).
  std::optional<StopJudge> judge_;
};

}  // namespace exc::sim
