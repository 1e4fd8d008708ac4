#pragma once
// The fidelity chart: the closed loop with each model variant against the most faithful one (the
// reference), each variant's tip, force and tracking differences from it and its CPU time relative to
// it, and the cheapest model within tolerance.
#include <string>
#include <vector>

#include "bench_runs.hpp"

namespace exc::bench {

// Tolerances of the recommendation (stated in the output and docs/bench.md).
constexpr double kTipTolerance = 0.01;       // m, RMS tip path difference
constexpr double kForceTolerance = 0.05;     // relative RMS cylinder-force difference
constexpr double kTrackingTolerance = 0.002; // m or rad, change of the worst joint's RMS tracking error
constexpr double kCostNoise = 0.15;          // CPU-time differences below this fraction are noise here

struct FidelityRow {
  std::string scene, fidelity;
  bool ok = false;
  bool reference = false;  // the variant the others are measured against (its differences are 0 by definition)
  std::string failure;
  double cpu_per_s = NAN;   // the least over the repeats
  double cost_ratio = NAN;  // cpu_per_s over the reference's
  double tip_rms = NAN, force_rel = NAN, tracking_diff = NAN, tracking = NAN;
  bool within = false, recommended = false;
};

// The worst joint's RMS tracking error of a run.
double worst_tracking(const ClosedLoopResult& r);
// Each variant run `repeats` times (the runs are deterministic: only the CPU time differs; the least
// is kept, the machine's load only ever adds to it).
std::vector<FidelityRow> fidelity_chart(const std::vector<BenchScene>& scenes, double duration, int repeats);
void write_fidelity_csv(const std::string& path, const std::vector<FidelityRow>& rows);

}  // namespace exc::bench
