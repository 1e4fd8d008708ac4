#pragma once
// Effort feasibility of a task before the run: the model's inverse dynamics along the
// whole desired trajectory, every control period, against the actuators' limits. Where the tip is
// below the terrain the soil will take part of the effort, so there only (1 - soil_margin) of each
// limit is counted as available.
//
// Time scaling in closed form: for q_s(t) = q(t / s) (a clamped spline with its knot times scaled by
// s is exactly that), tau_s = g(q) + (tau_1 - g(q)) / s^2, because M(q) qdd and the velocity terms
// both scale with 1/s^2 while gravity does not. So each sample and joint gives the least s that fits
// directly; the largest over the path is the timing scale the task needs. A pose whose gravity load
// alone exceeds a limit fits at no speed.
// Start-up code: allocates (the report's strings), runs in milliseconds.
#include <string>
#include <vector>

#include "control/task/trajectory.hpp"
#include "model/model.hpp"
#include "model/terrain.hpp"

namespace exc::control {

struct FeasibilityOptions {
  double sample_period = 1e-3;  // s: every control cycle
  double soil_margin = 0.3;     // fraction of each limit kept free for the soil where the tip is below ground
  Terrain terrain;              // the ground (flat or a profile)
  // What the actuators' dry friction takes of each limit while they move (N m, N; the nominal
  // machine's Coulomb level at the pumps' pressure on a hydraulic machine, 0 on force actuators).
  Vec4 friction = Vec4::Zero();
};

struct FeasibilityReport {
  bool ok = true;
  // The worst violation (when !ok), or the tightest point (when ok).
  double t = 0;                  // s, trajectory time
  int joint = -1;                // 0 swing .. 3 bucket
  double effort = 0;             // N m or N, what the path needs there
  double limit = 0;              // the available limit it exceeds (signed, the side it hits)
  bool in_soil = false;          // the available limit was reduced by the soil margin
  double time_scale = 1;         // least s (>= 1 when !ok) so that the path timed by s fits; inf: no s fits
  double samples = 0;            // how many points were checked
  // "task.path[1] -> task.path[2] at t = 3.20 s: the swing needs 118 kN m, limit 65 kN m ..."
  std::string message(const std::vector<double>& waypoint_times, const std::string& field) const;
};

FeasibilityReport check_effort_feasibility(const Model& model, const JointTrajectory& trajectory,
                                           const FeasibilityOptions& options = {});

// The same waypoints with every time scaled by s about the first (s > 0).
JointTrajectory scale_timing(const JointTrajectory& trajectory, double s);

}  // namespace exc::control
