#pragma once
// The stability maps: the largest stable step of every integrator against soil stiffness and joint
// speed, each controller's stability against gains, adaptation, noise, delay and mass error, and the
// hydraulic maps (the valve stage's gains and the outer law's against the plant's spool lag and bulk
// modulus). Each is a sweep spec (sweeps/stability_*.yaml) run in this process through the sweep's
// shard and merge (sweep/sweep.hpp); the merge's files are in OUT/<spec name>/.
#include <string>
#include <vector>

#include "bench_runs.hpp"

namespace exc::bench {

struct StepStability {
  std::string method, axis;
  double value = 0, largest_stable_step = NAN;
  std::string failure_above;  // what the plant's checks said at the next larger step
};

struct ControlStability {
  std::string controller, axis;
  double value = 0;
  bool ok = false;
  double tracking = NAN;
  std::string failure;
};

// One hydraulic map: its spec, runs and failures (failure kind -> runs) per controller.
struct HydraulicMap {
  std::string name, dir;
  int runs = 0, failed = 0;
  std::vector<std::string> lines;  // per controller and axis value with failures, for the summary table
};

struct StabilityMaps {
  std::vector<StepStability> step;
  std::vector<ControlStability> control;
  std::vector<HydraulicMap> hydraulic;  // empty with --quick
  std::vector<std::string> failed_merges;  // specs whose merge lost cases or a chart (the bench fails)
};

// Runs sweeps/stability_*.yaml from `sweeps_dir` on the scenes of `scenes_dir` (quick: the CI cut,
// fewer values, shorter runs, no hydraulic maps), each into out/<spec name>/.
StabilityMaps stability_maps(const std::string& sweeps_dir, const std::string& scenes_dir, const std::string& out,
                             bool quick);
void write_stability_csvs(const std::string& dir, const std::vector<StepStability>& steps,
                          const std::vector<ControlStability>& control);

}  // namespace exc::bench
