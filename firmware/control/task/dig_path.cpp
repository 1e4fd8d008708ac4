#include "control/task/dig_path.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "settings/settings_error.hpp"

namespace exc::control {
namespace {

std::string fmt(double v, int precision = 4) {
  std::ostringstream s;
  s.precision(precision);
  s << v;
  return s.str();
}

}  // namespace

std::string waypoint_place(const std::vector<double>& times, double t, const std::string& field) {
  for (std::size_t i = 0; i < times.size(); ++i)
    if (std::abs(times[i] - t) < 1e-9) return field + "[" + std::to_string(i) + "]";
  const auto it = std::upper_bound(times.begin(), times.end(), t);
  const std::size_t i = it == times.begin() ? 0 : static_cast<std::size_t>(it - times.begin()) - 1;
  if (i + 1 >= times.size()) return field + "[" + std::to_string(times.size() - 1) + "]";
  return field + "[" + std::to_string(i) + "] -> " + field + "[" + std::to_string(i + 1) + "]";
}

namespace {

// Sample times: a regular grid plus every waypoint time (so waypoints are checked exactly).
std::vector<double> sample_times(const std::vector<double>& waypoint_times, double period) {
  std::vector<double> ts;
  const double t0 = waypoint_times.front(), t1 = waypoint_times.back();
  const auto n = static_cast<long>(std::ceil((t1 - t0) / period - 1e-9));
  for (long k = 0; k <= n; ++k) ts.push_back(std::min(t1, t0 + static_cast<double>(k) * period));
  ts.insert(ts.end(), waypoint_times.begin(), waypoint_times.end());
  std::sort(ts.begin(), ts.end());
  std::vector<double> unique;
  for (double t : ts)
    if (unique.empty() || t - unique.back() > 1e-6) unique.push_back(t);
    else if (std::find(waypoint_times.begin(), waypoint_times.end(), t) != waypoint_times.end())
      unique.back() = t;  // keep the exact waypoint time
  return unique;
}

}  // namespace

void check_joint_trajectory(const Machine& machine, const JointTrajectory& trajectory,
                            const std::vector<double>& waypoint_times, const TrajectoryCheckOptions& options,
                            const std::string& file, const std::string& field) {
  const Vec4 lo = machine.q_min(), hi = machine.q_max(), vmax = machine.speed_max();
  for (double t : sample_times(waypoint_times, options.sample_period)) {
    Vec4 q, qd, qdd;
    trajectory.evaluate(t, q, qd, qdd);
    for (int j = 0; j < kNumActive; ++j) {
      const double margin = j == 0 ? 0.0 : options.length_margin;
      if (q[j] < lo[j] + margin || q[j] > hi[j] - margin)
        throw SettingsError(file, 0, 0, waypoint_place(waypoint_times, t, field),
                          std::string("at t = ") + fmt(t) + " s the " + kActiveNames[j] +
                              (j == 0 ? " angle is " : " cylinder length is ") + fmt(q[j], 6) +
                              (j == 0 ? " rad" : " m") + ", outside the allowed " + fmt(lo[j] + margin, 6) +
                              " .. " + fmt(hi[j] - margin, 6));
      if (options.check_speed && std::abs(qd[j]) > vmax[j])
        throw SettingsError(file, 0, 0, waypoint_place(waypoint_times, t, field),
                          std::string("at t = ") + fmt(t) + " s the " + kActiveNames[j] + " speed is " +
                              fmt(qd[j], 4) + (j == 0 ? " rad/s" : " m/s") + ", above the limit " +
                              fmt(vmax[j], 4) + " (slow the path down)");
    }
  }
}

JointTrajectory dig_trajectory(const Machine& machine, double swing, const std::vector<DigWaypoint>& path,
                               const TrajectoryCheckOptions& options, const std::string& file,
                               const std::string& field) {
  if (path.size() < 2) throw SettingsError(file, 0, 0, field, "needs at least 2 tip waypoints");
  std::vector<double> times;
  std::vector<Vec3> poses;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0 && !(path[i].t > path[i - 1].t))
      throw SettingsError(file, 0, 0, field + "[" + std::to_string(i) + "].t",
                        fmt(path[i].t) + " s must be later than the previous waypoint's " + fmt(path[i - 1].t) + " s");
    times.push_back(path[i].t);
    poses.emplace_back(path[i].pose.x, path[i].pose.z, path[i].pose.pitch);
  }
  // The waypoints themselves first, so that a bad one is named directly.
  const Vec4 lo = machine.q_min(), hi = machine.q_max();
  for (std::size_t i = 0; i < path.size(); ++i) {
    const std::string f = field + "[" + std::to_string(i) + "]";
    Vec4 q;
    const IkStatus st = inverse_kinematics(machine, swing, path[i].pose, q);
    if (st != IkStatus::ok) throw SettingsError(file, 0, 0, f, std::string("tip pose: ") + to_string(st));
    for (int j = 1; j < kNumActive; ++j)
      if (q[j] < lo[j] + options.length_margin || q[j] > hi[j] - options.length_margin)
        throw SettingsError(file, 0, 0, f, std::string("the ") + kActiveNames[j] + " cylinder length would be " + fmt(q[j], 6) +
                                       " m, outside the allowed " + fmt(lo[j] + options.length_margin, 6) + " .. " +
                                       fmt(hi[j] - options.length_margin, 6) + " (change x, z or pitch_deg)");
  }
  const CubicSpline<3> tip_path(times, poses);
  std::vector<double> ts = sample_times(times, options.sample_period);
  std::vector<Vec4> qs;
  for (double t : ts) {
    Vec3 p, pd, pdd;
    tip_path.evaluate(t, p, pd, pdd);
    const TipPose pose{p[0], p[1], p[2]};
    Vec4 q;
    const IkStatus s = inverse_kinematics(machine, swing, pose, q);
    if (s != IkStatus::ok)
      throw SettingsError(file, 0, 0, waypoint_place(times, t, field),
                        std::string("at t = ") + fmt(t) + " s the tip (x " + fmt(pose.x) + " m, z " + fmt(pose.z) +
                            " m, pitch " + fmt(pose.pitch * 180 / 3.14159265358979323846) + " deg): " + to_string(s));
    qs.push_back(q);
  }
  JointTrajectory trajectory(ts, qs);
  check_joint_trajectory(machine, trajectory, times, options, file, field);
  return trajectory;
}

}  // namespace exc::control
