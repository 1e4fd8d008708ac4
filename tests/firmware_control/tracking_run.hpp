#pragma once
// Runs one controller on a task against the model plant at 1 kHz, the way the firmware does:
// measurements -> state estimator -> controller -> plant; returns the tracking figures.
#include <yaml-cpp/yaml.h>

#include "closed_loop.hpp"
#include "control/controller_registry.hpp"
#include "control/estimation/state_estimator.hpp"
#include "control/task/task.hpp"

namespace exc::control::sim {

struct TrackingResult {
  Vec4 rms = Vec4::Zero(), max_abs = Vec4::Zero();
  Vec6 theta_hat = Vec6::Zero();
  int soil_steps = 0, saturated_steps = 0;
  bool ok = true;
};

// The law's input at time t as the firmware builds it (app/firmware_node.cpp): the estimator updated
// with the measured q, qd, and the task's desired motion at t.
inline ControlInput estimated_input(StateEstimator& est, const Vec4& q, const Vec4& qd, const Task& task, double t) {
  est.update(q, qd);
  ControlInput in;
  in.t = t;
  in.q = est.position();
  in.qd = est.velocity();
  in.qd_measured = qd;
  in.qdd = est.acceleration();
  task.trajectory.evaluate(t, in.q_d, in.qd_d, in.qdd_d);
  return in;
}

// applied_known: the law is told the efforts the plant applied last step (the model plant's actuators
// are ideal: what was commanded), as a hydraulic machine's pressures tell the firmware.
inline TrackingResult run_tracking(const Model& model, const Task& task, const std::string& kind,
                                   const ControllerConfig& cfg, const SoilTruth& soil, bool applied_known = false) {
  auto ctrl = make_controller(kind, model, cfg);
  ModelPlant plant(model, soil);
  Vec4 q0, qd0, qdd0;
  task.trajectory.evaluate(task.start_time(), q0, qd0, qdd0);
  plant.reset(q0, qd0);
  StateEstimator est(cfg.filter);
  TrackingResult r;
  Vec4 sum_sq = Vec4::Zero();
  const int steps = static_cast<int>((task.end_time() + 1.0) / cfg.period);
  Terrain ground;
  Vec4 last_tau = Vec4::Zero();
  ground.height = soil.terrain_height;
  for (int k = 0; k < steps; ++k) {
    const double t = task.start_time() + k * cfg.period;
    ControlInput in = estimated_input(est, plant.q(), plant.qd(), task, t);
    in.soil.site_map = &ground;
    if (applied_known && k > 0) {
      in.applied.valid = true;
      in.applied.effort = last_tau;
    }
    const TipLoad load = plant.soil_load();
    const ControlOutput out = ctrl->update(in);
    last_tau = out.tau;
    if (out.status != ModelStatus::ok || !plant.step(out.tau, load, cfg.period)) {
      r.ok = false;
      break;
    }
    const Vec4 e = in.q - in.q_d;
    sum_sq += e.cwiseProduct(e);
    r.max_abs = r.max_abs.cwiseMax(e.cwiseAbs());
    r.soil_steps += plant.in_soil() ? 1 : 0;
    r.saturated_steps += out.saturated ? 1 : 0;
    r.theta_hat = out.theta_hat;
  }
  r.rms = (sum_sq / steps).cwiseSqrt();
  return r;
}

}  // namespace exc::control::sim
