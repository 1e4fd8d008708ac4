#include "control/task/effort_feasibility.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "control/task/dig_path.hpp"
#include "model/closed_chain.hpp"
#include "model/workspace.hpp"

namespace exc::control {
namespace {

// Least s >= 0 with g + d / s^2 inside [lo, hi] (inf when g itself is outside).
double least_scale(double g, double d, double lo, double hi) {
  if (g > hi || g < lo) return std::numeric_limits<double>::infinity();
  if (d > 0) return std::sqrt(d / std::max(hi - g, 1e-300));
  if (d < 0) return std::sqrt(d / std::min(lo - g, -1e-300));
  return 0;
}

std::string effort_text(int joint, double v) {
  char b[64];
  if (joint == 0)
    std::snprintf(b, sizeof b, "%.1f kN m", v * 1e-3);
  else
    std::snprintf(b, sizeof b, "%.1f kN", v * 1e-3);
  return b;
}

}  // namespace

FeasibilityReport check_effort_feasibility(const Model& model, const JointTrajectory& trajectory,
                                           const FeasibilityOptions& options) {
  FeasibilityReport r;
  r.time_scale = 0;
  Workspace ws(model);
  const Vec4 hi = model.machine.effort_max(), lo = model.machine.effort_min();
  const double t0 = trajectory.start_time(), t1 = trajectory.end_time();
  const auto n = static_cast<long>(std::ceil((t1 - t0) / options.sample_period));
  Vec4 q, qd, qdd, tau, g;
  double worst_ratio = -1;  // largest |effort| / available limit seen
  for (long i = 0; i <= n; ++i) {
    const double t = std::min(t1, t0 + static_cast<double>(i) * options.sample_period);
    trajectory.evaluate(t, q, qd, qdd);
    if (!update_closed_chain(model, ws, q, Vec4::Zero()).ok()) continue;  // the task check names such poses
    bias_forces(model, ws, g);  // at rest: gravity alone
    const bool in_soil = ws.rho.y() < options.terrain.height_at(ws.rho.x());
    update_closed_chain(model, ws, q, qd);
    inverse_dynamics(model, ws, qdd, Vec2::Zero(), tau);
    const double keep = in_soil ? 1 - options.soil_margin : 1;
    r.samples += 1;
    for (int j = 0; j < 4; ++j) {
      const double h = hi[j] * keep - options.friction[j], l = lo[j] * keep + options.friction[j];
      const double s = least_scale(g[j], tau[j] - g[j], l, h);
      const double limit = tau[j] >= 0 ? h : l;
      const double ratio = tau[j] / limit;
      if (s > r.time_scale || (s == r.time_scale && ratio > worst_ratio)) {
        r.time_scale = s;
        r.t = t;
        r.joint = j;
        r.effort = tau[j];
        r.limit = limit;
        r.in_soil = in_soil;
        worst_ratio = ratio;
      }
    }
  }
  r.ok = r.time_scale <= 1;
  return r;
}

std::string FeasibilityReport::message(const std::vector<double>& waypoint_times, const std::string& field) const {
  std::string m = waypoint_place(waypoint_times, t, field);
  char b[96];
  std::snprintf(b, sizeof b, " at t = %.3f s: the ", t);
  m += b;
  m += kActiveNames[static_cast<std::size_t>(joint)];
  m += " needs " + effort_text(joint, effort) + ", its limit is " + effort_text(joint, limit);
  if (in_soil) m += " (the actuator's limit less the soil margin: the tip is below ground)";
  if (std::isinf(time_scale)) {
    m += "; gravity alone exceeds it there, so no timing fits: move the pose";
  } else {
    const double duration = waypoint_times.empty() ? 0 : waypoint_times.back() - waypoint_times.front();
    std::snprintf(b, sizeof b, "; it fits with the timing scaled by %.2f (%.2f s instead of %.2f s)", time_scale,
                  duration * time_scale, duration);
    m += b;
  }
  return m;
}

JointTrajectory scale_timing(const JointTrajectory& trajectory, double s) {
  std::vector<double> times = trajectory.times();
  const double t0 = times.front();
  for (double& t : times) t = t0 + (t - t0) * s;
  return JointTrajectory(times, trajectory.points());
}

}  // namespace exc::control
