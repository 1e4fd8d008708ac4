#include "control/task/work_cycle.hpp"

#include <cmath>

#include "settings/settings_error.hpp"

namespace exc::control {
namespace {

constexpr double kSample = 0.01;  // s between the knots of a move (the dig pass's IK grid too)

// q(s) of the quintic from (q0, 0, a0) to (q1, 0, a1) over T: at rest at both ends, with the given
// accelerations there, so that it joins a spline ending or starting at rest with continuous
// position, velocity and acceleration; without end accelerations it is the minimum-jerk move.
Vec4 quintic_at(const Vec4& q0, const Vec4& a0, const Vec4& q1, const Vec4& a1, double T, double t) {
  const double s = t / T, s2 = s * s, s3 = s2 * s, s4 = s3 * s, s5 = s4 * s;
  const Vec4 d = q1 - q0;
  const Vec4 A0 = a0 * (T * T), A1 = a1 * (T * T);  // accelerations in the normalised time
  // Coefficients of c3 s^3 + c4 s^4 + c5 s^5 beyond q0 + A0 s^2 / 2, from the six end conditions.
  const Vec4 c3 = 10 * d - 1.5 * A0 + 0.5 * A1;
  const Vec4 c4 = -15 * d + 1.5 * A0 - A1;
  const Vec4 c5 = 6 * d - 0.5 * A0 + 0.5 * A1;
  return q0 + 0.5 * A0 * s2 + c3 * s3 + c4 * s4 + c5 * s5;
}

// Appends the knots of a move from the last knot (at rest, acceleration a0) to q1 (at rest,
// acceleration a1) over T, the last knot at q1 when `include_end`.
void append_move(CycleKnots& k, const Vec4& a0, const Vec4& q1, const Vec4& a1, double T, bool include_end) {
  const Vec4 q0 = k.points.back();
  const double t0 = k.times.back();
  const int n = std::max(1, static_cast<int>(std::lround(T / kSample)));
  for (int i = 1; i <= n; ++i) {
    if (i == n && !include_end) break;
    const double t = T * static_cast<double>(i) / n;
    k.times.push_back(t0 + t);
    k.points.push_back(quintic_at(q0, a0, q1, a1, T, t));
  }
}

// The acceleration a knot sequence's spline has just inside its ends (it is at rest there).
void end_accelerations(const CycleKnots& c, Vec4& at_start, Vec4& at_end) {
  const JointTrajectory spline(c.times, c.points);
  Vec4 q, qd;
  spline.evaluate(c.times.front() + 1e-9, q, qd, at_start);
  spline.evaluate(c.times.back() - 1e-9, q, qd, at_end);
}

}  // namespace

CycleKnots repeat_cycle(const CycleKnots& cycle, int count, double gap, std::vector<double>& cycle_starts) {
  Vec4 a_start, a_end;
  end_accelerations(cycle, a_start, a_end);
  CycleKnots all{{cycle.times.front()}, {cycle.points.front()}};
  cycle_starts.clear();
  for (int k = 0; k < count; ++k) {
    if (k > 0) append_move(all, a_end, cycle.points.front(), a_start, gap, true);  // the return move
    cycle_starts.push_back(all.times.back());
    const double shift = all.times.back() - cycle.times.front();
    for (std::size_t i = 1; i < cycle.times.size(); ++i) {
      all.times.push_back(cycle.times[i] + shift);
      all.points.push_back(cycle.points[i]);
    }
  }
  return all;
}

CycleKnots truck_loading_cycle(const Machine& machine, double dig_swing, const std::vector<DigWaypoint>& path,
                               const DumpPose& dump, const TruckCycleTimes& times, const TrajectoryCheckOptions& options,
                               const std::string& file, const std::string& field) {
  // The dig pass as the dig task builds it (checked and named there), then its knots.
  const JointTrajectory pass = dig_trajectory(machine, dig_swing, path, options, file, field + ".path");
  CycleKnots c{pass.times(), pass.points()};
  const auto pose_at = [&](const TipPose& tip, const std::string& where) {
    Vec4 q;
    const IkStatus st = inverse_kinematics(machine, dump.swing, tip, q);
    if (st != IkStatus::ok) throw SettingsError(file, 0, 0, field + ".dump" + where, std::string("tip pose: ") + to_string(st));
    return q;
  };
  const Vec4 curled = pose_at(dump.curled, "");
  TipPose open = dump.curled;
  open.pitch = dump.open_pitch;
  const Vec4 opened = pose_at(open, ".open_pitch_deg");
  Vec4 a_start, a_end;
  end_accelerations(c, a_start, a_end);
  // Lift and swing to the truck, open the bucket, each from rest to rest (minimum jerk), joined to
  // the dig pass with its own end acceleration so the joint stays C2.
  append_move(c, Vec4::Zero(), curled, Vec4::Zero(), times.to_dump, true);
  append_move(c, Vec4::Zero(), opened, Vec4::Zero(), times.dump, true);
  return c;
}

}  // namespace exc::control
