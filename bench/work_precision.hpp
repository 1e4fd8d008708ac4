#pragma once
// The work-precision chart: every integrator x formulation x step against a fine RK4 reference,
// tip error against CPU time per simulated second, and the Pareto front per scene.
#include <string>
#include <vector>

#include "bench_runs.hpp"

namespace exc::bench {

struct WorkPoint {
  std::string scene, method;
  double step = 0, cpu_per_s = 0, tip_rms = 0, constraint = 0, energy = 0;
  bool ok = false;
  std::string failure;
  bool pareto = false;
};

std::vector<WorkPoint> work_precision(const std::vector<BenchScene>& scenes, const std::vector<double>& steps,
                                      double reference_step, std::vector<OpenLoopResult>& references);
void write_work_csv(const std::string& path, const std::vector<WorkPoint>& points);

}  // namespace exc::bench
