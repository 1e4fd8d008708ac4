#pragma once
// The project's plant against MuJoCo on the same states and efforts: step time, constraint error,
// tip path against the fine reference, the controller step against mj_inverse.
#include <string>
#include <vector>

#include "bench_runs.hpp"

namespace exc::bench {

struct PeerResult {
  std::string scene;
  double plant_step_us = NAN, constraint_error = NAN, tip_rms = NAN;           // ours, default method
  double augmented_constraint_error = NAN;                                     // ours, augmented + Baumgarte
  double mujoco_step_us = NAN, mujoco_constraint_error = NAN, mujoco_tip_rms = NAN;
  double control_step_us = NAN, mujoco_inverse_us = NAN, inverse_dynamics_us = NAN;
  double dynamics_step_us = NAN;  // the plant's integrator step alone (dynamics + integration)
  std::string mujoco_status = "not available, peer skipped";
  std::vector<Vec3> reference_tip, ours_tip, mujoco_tip;
};

std::vector<PeerResult> peer_comparison(const std::vector<BenchScene>& scenes,
                                        const std::vector<OpenLoopResult>& references, const std::string& out_dir);
void write_peer_csvs(const std::string& dir, const std::vector<PeerResult>& peers);

}  // namespace exc::bench
