#pragma once
// The fidelity chart: the closed loop with each model fidelity against the most faithful driven
// model, CPU against the tip, force and tracking differences, and the cheapest model within tolerance.
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
  std::string failure;
  double cpu_per_s = NAN, tip_rms = NAN, force_rel = NAN, tracking_diff = NAN, tracking = NAN;
  bool within = false, recommended = false;
};

// The worst joint's RMS tracking error of a run.
double worst_tracking(const ClosedLoopResult& r);
std::vector<FidelityRow> fidelity_chart(const std::vector<BenchScene>& scenes, double duration);
void write_fidelity_csv(const std::string& path, const std::vector<FidelityRow>& rows);

}  // namespace exc::bench
