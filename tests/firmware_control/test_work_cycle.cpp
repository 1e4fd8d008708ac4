// Work cycles: a repeated task is one C2 trajectory whose return moves join the cycles smoothly, and
// the truck-loading cycle reaches its dump pose.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>

#include "control/task/task.hpp"
#include "model/closed_chain.hpp"
#include "model/workspace.hpp"
#include "scenes.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

std::string repeated(const char* task, const std::string& extra) {
  std::string t = task;
  const std::string type = "task:\n  type: ";
  const auto at = t.find('\n', t.find(type) + type.size());
  t.insert(at + 1, extra);
  return t;
}

// Largest jump of q, qd and qdd across a time t, from the spline evaluated just before and after
// (a C2 trajectory has none beyond what 2 eps of motion explains).
Vec3 jumps(const JointTrajectory& tr, double t) {
  const double eps = 1e-7;
  Vec4 q0, qd0, qdd0, q1, qd1, qdd1;
  tr.evaluate(t - eps, q0, qd0, qdd0);
  tr.evaluate(t + eps, q1, qd1, qdd1);
  return Vec3((q1 - q0).cwiseAbs().maxCoeff(), (qd1 - qd0).cwiseAbs().maxCoeff(), (qdd1 - qdd0).cwiseAbs().maxCoeff());
}

}  // namespace

TEST_CASE("firmware/work cycles: repeat N gives N cycles joined by return moves continuous in position, velocity and acceleration") {
  const Machine m = reference_machine();
  const Task once = read_task(settings::Document::parse(sim::kFreeMotionTask, "test"), m);
  const Task three = read_task(settings::Document::parse(repeated(sim::kFreeMotionTask, "  repeat: 3\n  return_time: 4\n"), "test"), m);
  REQUIRE(once.cycles() == 1);
  REQUIRE(three.cycles() == 3);
  const double length = once.end_time() - once.start_time();
  CHECK(three.end_time() == doctest::Approx(once.start_time() + 3 * length + 2 * 4.0));
  for (int k = 1; k < 3; ++k) {
    // Cycle k starts where the task starts, after a return move from where cycle k-1 ended.
    const double start = three.cycle_starts[k];
    CHECK(start == doctest::Approx(once.start_time() + k * (length + 4.0)));
    Vec4 q_first, q_here, qd, qdd;
    once.trajectory.evaluate(once.start_time(), q_first, qd, qdd);
    three.trajectory.evaluate(start, q_here, qd, qdd);
    CHECK((q_here - q_first).cwiseAbs().maxCoeff() < 1e-9);
    // Smooth at both ends of the return move (cycle end -> return, return -> next cycle).
    for (double t : {start - 4.0, start}) {
      const Vec3 j = jumps(three.trajectory, t);
      INFO("t = " << t << ": jumps " << j.transpose());
      CHECK(j[0] < 1e-6);
      CHECK(j[1] < 1e-5);
      CHECK(j[2] < 1e-3);
    }
  }
  // The cycles between the returns are the task itself.
  Vec4 a, b, qd, qdd;
  once.trajectory.evaluate(once.start_time() + 1.3, a, qd, qdd);
  three.trajectory.evaluate(three.cycle_starts[2] + 1.3, b, qd, qdd);
  CHECK((a - b).cwiseAbs().maxCoeff() < 2e-3);  // the spline through the joined knots, not the same spline
}

TEST_CASE("firmware/work cycles: the truck-loading cycle digs, swings 90 degrees to its dump pose, opens the bucket and returns") {
  const Machine m = reference_machine();
  const char* yaml = R"(
task:
  type: truck_loading
  swing: 0.0
  path:
    - {t: 0.0,  x: 7.0, z: 0.8,   pitch_deg: 40}
    - {t: 2.0,  x: 6.8, z: 0.05,  pitch_deg: 35}
    - {t: 3.5,  x: 6.5, z: -0.35, pitch_deg: 25}
    - {t: 6.0,  x: 5.6, z: -0.40, pitch_deg: 10}
    - {t: 8.0,  x: 5.1, z: -0.15, pitch_deg: -30}
    - {t: 10.0, x: 5.3, z: 1.0,   pitch_deg: -20}
  dump: {swing_deg: 90, x: 6.0, z: 3.0, pitch_deg: 10, open_pitch_deg: 55}
  times: {to_dump: 5, dump: 2, back: 5}
  repeat: 2
)";
  const Task t = read_task(settings::Document::parse(yaml, "test"), m);
  REQUIRE(t.type == TaskType::truck_loading);
  REQUIRE(t.cycles() == 2);
  CHECK(t.cycle_starts[1] == doctest::Approx(10 + 5 + 2 + 5));
  CHECK(t.end_time() == doctest::Approx(2 * 17 + 2 * 5));
  // At the dump (end of to_dump) the swing is at 90 degrees and the tip where the scene puts it.
  const Model model = build_model(m);
  Workspace ws(model);
  Vec4 q, qd, qdd;
  t.trajectory.evaluate(15.0, q, qd, qdd);
  CHECK(q[0] == doctest::Approx(1.5707963).epsilon(1e-4));
  REQUIRE(update_closed_chain(model, ws, q, Vec4::Zero()).ok());
  CHECK(ws.rho.x() == doctest::Approx(6.0).epsilon(1e-3));
  CHECK(ws.rho.y() == doctest::Approx(3.0).epsilon(1e-3));
  // At the end: back at the pass's first pose, at rest.
  Vec4 q0, q_end;
  t.trajectory.evaluate(0, q0, qd, qdd);
  t.trajectory.evaluate(t.end_time(), q_end, qd, qdd);
  CHECK((q_end - q0).cwiseAbs().maxCoeff() < 1e-9);
  // Smooth everywhere inside: no jump larger than 2 eps of motion at any knot.
  double worst_acc_jump = 0, worst_at = 0, smallest_gap = 1;
  const std::vector<double>& knots = t.trajectory.times();
  // Interior knots (before the start and after the end the trajectory holds, at rest).
  for (std::size_t i = 1; i + 1 < knots.size(); ++i) {
    const double j = jumps(t.trajectory, knots[i])[2];
    if (j > worst_acc_jump) worst_acc_jump = j, worst_at = knots[i];
    if (i > 0) smallest_gap = std::min(smallest_gap, knots[i] - knots[i - 1]);
  }
  INFO("worst at t = " << worst_at << ", smallest knot gap " << smallest_gap);
  CHECK(worst_acc_jump < 1e-3);
}
