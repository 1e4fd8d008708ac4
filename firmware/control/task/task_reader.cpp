// The `task:` section: every field declared once with the settings reader; the trajectory built
// and checked against the machine's limits, a failed check named at the waypoint's line.
#include "control/task/task_reader.hpp"

#include <algorithm>
#include <cmath>

#include "control/task/work_cycle.hpp"

namespace exc::control {
namespace {

using settings::format_number;
using settings::Need;
using settings::SectionReader;

constexpr double kPi = 3.14159265358979323846;
constexpr double kTimeMax = 1e5;
constexpr std::size_t kMaxWaypoints = 100000;

void read_effort_check(SectionReader& r, TaskEffortCheck& c) {
  r.flag("check", c.check, "refuse a path the actuators cannot drive");
  r.number("soil_margin", c.soil_margin, {0, 0.9}, "", "fraction of each limit kept for the soil below ground");
  r.flag("fit_timing", c.fit_timing, "instead of refusing, slow the whole path down until it fits");
  r.finish();
}

// A tip path (the dig pass): timed tip poses.
std::vector<DigWaypoint> read_path(SectionReader& r) {
  std::vector<DigWaypoint> path;
  r.sections("path", 2, kMaxWaypoints, "timed tip poses", [&path](SectionReader& w, std::size_t) {
    DigWaypoint wp;
    double pitch_deg = 0;
    w.number("t", wp.t, {0, kTimeMax}, "s", "time of the pose", Need::required);
    w.number("x", wp.pose.x, {0, 100}, "m", "tip from the swing axis", Need::required);
    w.number("z", wp.pose.z, {-100, 100}, "m", "tip world height", Need::required);
    w.number("pitch_deg", pitch_deg, {-360, 360}, "deg", "angle of M->L above swing x", Need::required);
    wp.pose.pitch = pitch_deg * kPi / 180;
    path.push_back(wp);
  }, Need::required);
  return path;
}

void read_joint_waypoints(SectionReader& r, const Machine& machine, Task& task) {
  Vec4 lo = machine.q_min(), hi = machine.q_max();
  for (int j = 0; j < kNumActive; ++j) {
    if (!std::isfinite(lo[j])) lo[j] = -1e3;
    if (!std::isfinite(hi[j])) hi[j] = 1e3;
  }
  std::vector<Vec4> qs;
  r.sections("waypoints", 2, kMaxWaypoints, "timed joint positions", [&](SectionReader& w, std::size_t) {
    double t = 0;
    Vec4 q = Vec4::Zero();
    w.number("t", t, {0, kTimeMax}, "s", "time of the waypoint", Need::required);
    if (!task.waypoint_times.empty() && !(t > task.waypoint_times.back()))
      w.fail("t", format_number(t) + " s must be later than the previous waypoint's " +
                      format_number(task.waypoint_times.back()) + " s");
    w.numbers("q", q, lo, hi, "", "[swing rad, L_boom m, L_arm m, L_bucket m]", Need::required);
    task.waypoint_times.push_back(t);
    qs.push_back(q);
  }, Need::required);
  task.trajectory = JointTrajectory(task.waypoint_times, qs);
}

void read_dump(SectionReader& d, DumpPose& dump) {
  double swing_deg = 0, pitch_deg = 0, open_deg = 0;
  d.number("swing_deg", swing_deg, {-180, 180}, "deg", "the swing angle over the truck", Need::required);
  d.number("x", dump.curled.x, {0, 100}, "m", "tip from the swing axis", Need::required);
  d.number("z", dump.curled.z, {-100, 100}, "m", "tip world height", Need::required);
  d.number("pitch_deg", pitch_deg, {-360, 360}, "deg", "bucket curled, M->L above swing x", Need::required);
  d.number("open_pitch_deg", open_deg, {-360, 360}, "deg", "bucket opened to dump", Need::required);
  d.finish();
  dump.swing = swing_deg * kPi / 180;
  dump.curled.pitch = pitch_deg * kPi / 180;
  dump.open_pitch = open_deg * kPi / 180;
}

void read_cycle_times(SectionReader& t, TruckCycleTimes& times) {
  t.number("to_dump", times.to_dump, {0.5, 600}, "s", "from the end of the dig pass to the dump pose");
  t.number("dump", times.dump, {0.2, 600}, "s", "opening the bucket");
  t.number("back", times.back, {0.5, 600}, "s", "swinging back to the start of the next pass");
  t.finish();
}

// The truck-loading cycles: each after the first starts with the swing back (the return move); the
// last one swings back too, so the machine ends where the next pass would start.
void build_truck_loading(SectionReader& r, const Machine& machine, const TrajectoryCheckOptions& options, int repeat,
                         Task& task) {
  SectionReader d = r.section("dump", "the tip pose over the truck", Need::required);
  DumpPose dump;
  read_dump(d, dump);
  SectionReader t = r.section("times", "the cycle's move times");
  TruckCycleTimes times;
  read_cycle_times(t, times);
  const CycleKnots cycle = truck_loading_cycle(machine, task.swing, task.path, dump, times, options, r.file(), r.path());
  const CycleKnots all = repeat_cycle(cycle, repeat + 1, times.back, task.cycle_starts);
  const std::size_t last_start = static_cast<std::size_t>(
      std::lower_bound(all.times.begin(), all.times.end(), task.cycle_starts.back()) - all.times.begin());
  task.cycle_starts.pop_back();
  task.trajectory = JointTrajectory(std::vector<double>(all.times.begin(), all.times.begin() + last_start + 1),
                                    std::vector<Vec4>(all.points.begin(), all.points.begin() + last_start + 1));
  check_joint_trajectory(machine, task.trajectory, task.cycle_starts, options, r.file(), r.path() + ".cycle");
}

void build_task(SectionReader& r, const Machine& machine, const TrajectoryCheckOptions& options, Task& task) {
  int repeat = 1;
  double return_time = 3;
  r.whole("repeat", repeat, 1, 1000, "", "work cycles");
  if (task.type != TaskType::truck_loading)
    r.number("return_time", return_time, {0.1, 600}, "s", "the return move between work cycles");
  if (task.type == TaskType::joint_waypoints) {
    read_joint_waypoints(r, machine, task);
    check_joint_trajectory(machine, task.trajectory, task.waypoint_times, options, r.file(), r.path() + ".waypoints");
  } else {
    r.number("swing", task.swing, {-kPi, kPi}, "rad", "the held swing angle of the dig pass");
    task.path = read_path(r);
    for (const DigWaypoint& w : task.path) task.waypoint_times.push_back(w.t);
    if (task.type == TaskType::truck_loading) {
      build_truck_loading(r, machine, options, repeat, task);
      return;
    }
    task.trajectory = dig_trajectory(machine, task.swing, task.path, options, r.file(), r.path() + ".path");
  }
  // Work cycles of a joint or dig task: one spline through the repeated knots.
  if (repeat > 1) {
    const CycleKnots once{task.trajectory.times(), task.trajectory.points()};
    const CycleKnots all = repeat_cycle(once, repeat, return_time, task.cycle_starts);
    task.trajectory = JointTrajectory(all.times, all.points);
    check_joint_trajectory(machine, task.trajectory, task.cycle_starts, options, r.file(), r.path() + ".cycle");
  } else {
    task.cycle_starts = {task.trajectory.start_time()};
  }
}

}  // namespace

Task read_task(SectionReader& r, const Machine& machine, const TrajectoryCheckOptions& options) {
  if (!r.present()) r.fail_here("missing: the firmware needs a task (type: " + kTaskTypes.names() + ")");
  if (!r.has("type")) r.fail("type", "missing; allowed values: " + kTaskTypes.names());
  Task task;
  r.choice("type", task.type, kTaskTypes, "what the machine does");
  try {
    build_task(r, machine, options, task);
  } catch (const SettingsError& e) {
    r.rethrow_placed(e);  // a limit check names its waypoint: at that waypoint's line
  }
  SectionReader efforts = r.section("efforts", "the effort check before the run");
  read_effort_check(efforts, task.efforts);
  r.finish();
  return task;
}

Task read_task(const settings::Document& scene, const Machine& machine, const TrajectoryCheckOptions& options) {
  SectionReader top(scene);
  SectionReader task = top.section("task", "what the machine does");
  return read_task(task, machine, options);
}

}  // namespace exc::control
