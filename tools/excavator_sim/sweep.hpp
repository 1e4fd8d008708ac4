#pragma once
// Sweeps: many closed-loop runs of a scene (or of several), numbered deterministically, run in shards
// that any engine can schedule (GNU parallel, Slurm job arrays, a plain loop) and merged afterwards.
//
//   sweep:
//     scene: scenes/dig.yaml          # relative to the spec file (or scenes: [a, b]: case i on
//                                     # scene i mod their number)
//     controllers: [pid, adaptive]
//     cases: 1000                     # seeded random draws, case i from seed + i
//     seed: 1
//     duration: 10                    # s per run (default: the scene's)
//     perturbations:                  # each drawn uniformly in [min, max] per case
//       model_mass: [-0.2, 0.2]       # the firmware's link masses x (1 + value)
//       soil_stiffness: [0.5, 3]      # the plant's soil K x value
//       position_noise: [0, 1e-4]     # m (rad on the swing), 1 sigma
//       delay_cycles: [0, 2]          # whole cycles, drawn as integers
//     faults: [bus_burst, sensor_freeze, sensor_jump, actuator_loss, actuator_jam, rock, pump_loss]
//                                     # the fault campaign (fault_campaign.hpp): one fault per case,
//                                     # its kind drawn from the list, its start, length, joint and
//                                     # size drawn too
//
// Case i's perturbation depends on (seed, i) only, so a shard computes exactly the cases a single
// process would, and any set of shard files merges into the same table.
#include <filesystem>
#include <string>
#include <vector>

#include "harness/lockstep_run.hpp"

namespace exc::sim {

struct SweepRange {
  bool given = false;
  double min = 0, max = 0;
};

struct SweepSpec {
  std::string file;
  std::string scene_path;                // the first of scene_paths
  std::vector<std::string> scene_paths;  // `scene`, or `scenes`: case i runs scene i mod their number
  std::vector<std::string> controllers{"pid", "adaptive"};
  int cases = 1;
  unsigned seed = 1;
  double duration = 0;
  SweepRange model_mass, soil_stiffness, position_noise, delay_cycles;
  std::vector<std::string> faults;  // fault kinds to draw from (empty: no fault)
};

// Reads a sweep spec (opened and parsed once; errors name file, line, column and field).
SweepSpec load_sweep_spec(const std::string& path);

struct SweepCase {
  int id = 0;
  double model_mass = 0, soil_stiffness = 1, position_noise = 0;
  int delay_cycles = 0;
  std::string fault = "none";
  double fault_start = 0, fault_duration = 0, fault_magnitude = 0;
  int fault_joint = 0;
  int scene = 0;  // index into the spec's scene_paths
};
SweepCase sweep_case(const SweepSpec& spec, int id);

// Runs the cases id = shard, shard + shards, ... and writes one JSON line per case to `out`.
// Returns the number of cases run.
int run_sweep_shard(const SweepSpec& spec, int shard, int shards, const std::filesystem::path& out, bool progress);

// Merges shard files into out_dir/sweep.csv and out_dir/sweep.json (failures by region, missing
// cases). Returns false when cases are missing (named in the JSON and on stderr).
bool merge_sweep(const SweepSpec& spec, const std::vector<std::filesystem::path>& shard_files,
                 const std::filesystem::path& out_dir);

}  // namespace exc::sim
