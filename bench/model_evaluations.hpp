#pragma once
// The closed-chain model's evaluation as the loop makes it, once per node and cycle:
// update_closed_chain, mass_matrix and bias_forces (the firmware's law without the passive angles,
// the plant's integrator with them), over a set of states. Each node and path has its own function,
// so that callgrind counts them apart (excavator-loop-bench --split); the model passed chooses the
// path and must be the one the name says.
#include <cstddef>
#include <vector>

#include "model/workspace.hpp"

namespace exc::bench {

struct ActiveState {
  Vec4 q_a, qd_a;
};

// n states with every cylinder inside its stroke (5 % from each end), the swing anywhere, and rates
// of the machine's size (cylinders to 0.5 m/s, swing to 1 rad/s); seeded, so every run draws the same.
std::vector<ActiveState> random_valid_states(const Model& model, std::size_t n, unsigned seed);

// Each returns a sum of the results (so that nothing is optimised away); NaN if an evaluation failed.
double firmware_evaluations_planar(const Model& model, Workspace& ws, const std::vector<ActiveState>& states);
double firmware_evaluations_general(const Model& model, Workspace& ws, const std::vector<ActiveState>& states);
double plant_evaluations_planar(const Model& model, Workspace& ws, const std::vector<ActiveState>& states);
double plant_evaluations_general(const Model& model, Workspace& ws, const std::vector<ActiveState>& states);

}  // namespace exc::bench
