#pragma once
// What excavator-plant-bench drives the plant with and probes it by: timing statistics, the scene's
// task through joint-space computed torque (force actuators) or through the valves (the hydraulic
// machine), and the stiff-clay stability probe. Bench drivers, not the firmware's controllers.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "control/task/task.hpp"
#include "model/closed_chain.hpp"
#include "sim_plant/plant.hpp"

namespace exc::bench {

using plant::PlantState;

struct Stats {
  double median = 0, p99 = 0, max = 0;
};

// Median, 99th percentile and maximum of a non-empty sample.
Stats stats(std::vector<double> v);


// Joint-space computed torque on the scene's task (no soil compensation): what drives the dig scene
// here, so that the plant's cost is measured on the real motion. Not the firmware's controller.
struct TaskDriver {
  control::Task task;
  Model model;
  Workspace ws;
  TaskDriver(const control::Task& t, const Machine& m) : task(t), model(build_model(m)), ws(model) {}
  Vec4 effort(double t, const PlantState& s) {
    Vec4 q, qd, qdd;
    task.trajectory.evaluate(std::min(t, task.end_time()), q, qd, qdd);
    const Vec4 kp(400, 400, 400, 400), kd(40, 40, 40, 40);
    const Vec4 a = qdd + kp.cwiseProduct(q - s.q_a) + kd.cwiseProduct(qd - s.qd_a);
    Vec4 tau = Vec4::Zero();
    if (update_closed_chain(model, ws, s.q_a, s.qd_a).ok()) inverse_dynamics(model, ws, a, Vec2::Zero(), tau);
    return tau;
  }
};

// The hydraulic machine on the scene's task: each valve opened for the desired velocity plus a
// correction of the position error over the function's speed limit (the flow law's u = qd_d - K_p e
// at the compensated meter-in's speed-limit flow, past the dead zone of its direction). What drives
// the shipped, valve-commanded dig here; not the firmware's valve stage.
struct ValveDriver {
  control::Task task;
  Vec4 speed_max, dead_extend, dead_retract;
  explicit ValveDriver(const control::Task& t, const Machine& m)
      : task(t), speed_max(m.speed_max()), dead_extend(m.hydraulics.dead_zone_extend),
        dead_retract(m.hydraulics.dead_zone_retract) {}
  Vec4 opening(double t, const PlantState& s) const {
    Vec4 q, qd, qdd, x;
    task.trajectory.evaluate(std::min(t, task.end_time()), q, qd, qdd);
    for (int i = 0; i < 4; ++i) {
      const double a = std::clamp((qd[i] + 2.0 * (q[i] - s.q_a[i])) / speed_max[i], -1.0, 1.0);
      const double d = a >= 0 ? dead_extend[i] : dead_retract[i];
      x[i] = a == 0 ? 0.0 : std::copysign(d + (1 - d) * std::abs(a), a);
    }
    return x;
  }
};

// The stiff-clay stability probe (as tests/plant/test_stability.cpp): the reference pose with the
// tip 0.1 m deep, moving into the soil, efforts holding the weight, 2 s. False, with the plant's
// check in `why`, when a check stopped it.
bool stable_in_stiff_clay(const plant::Scene& base, const std::string& m, plant::Formulation f, double h,
                          std::string& why);

}  // namespace exc::bench
