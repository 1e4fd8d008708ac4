#pragma once
// The control step's and the plant step's timing over the first and the last simulated second of a
// lockstep run (a cycle's cost must not depend on the run's history, docs/floating-point.md): the
// counters copied at the windows' edges in the loop (the loop's own copies, no allocation), the
// figures read from the histograms after it. The last second is left empty when the run stops
// before it begins; on a target (no node in this process) both are.
#include <cstdint>

#include "diagnostics/perf_counter.hpp"
#include "harness/lockstep_run.hpp"

namespace exc::sim {

// A counter's figures (each its bucket's upper edge).
Timing timing_of(const diagnostics::PerfCounter& c);
// The figures of the samples `after` recorded since it was `before` (a copy of the same counter
// taken earlier).
Timing timing_between(const diagnostics::PerfCounter& before, const diagnostics::PerfCounter& after);

class TimingWindows {
 public:
  TimingWindows(std::int64_t cycles, double period);
  // Before cycle k, and after `cycles_run` cycles; `control` null on a target.
  void before_cycle(std::int64_t k, const diagnostics::PerfCounter* control, const diagnostics::PerfCounter& plant);
  void after_cycle(std::int64_t cycles_run, const diagnostics::PerfCounter* control, const diagnostics::PerfCounter& plant);
  // The windows of a run that lasted `cycles_run` cycles, its counters at the end, into r.
  void finish(RunRecord& r, std::int64_t cycles_run, const diagnostics::PerfCounter* control,
              const diagnostics::PerfCounter& plant) const;

 private:
  double period_;
  std::int64_t first_end_, last_begin_;
  diagnostics::PerfCounter control_first_end_, plant_first_end_, control_last_begin_, plant_last_begin_;
  bool first_taken_ = false, last_taken_ = false;
};

}  // namespace exc::sim
