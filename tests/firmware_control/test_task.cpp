#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "control/task/task.hpp"
#include "model/closed_chain.hpp"
#include "scenes.hpp"
#include "settings_error_check.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

Task parse(const std::string& yaml) {
  return read_task(settings::Document::parse(yaml, "scene.yaml"), reference_machine());
}

// A bad task's error: scene.yaml, the field, the place where `at` begins in the yaml, the reason part.
void check_error(const std::string& yaml, const std::string& field, const std::string& at, const std::string& reason) {
  CAPTURE(yaml);
  try {
    parse(yaml);
    FAIL("no error");
  } catch (const SettingsError& e) {
    exc::test::check_settings_error(e, "scene.yaml", yaml, field, at, reason);
  }
}

}  // namespace

TEST_CASE("firmware/task joint waypoints parse into a spline through them") {
  const Task task = parse(sim::kFreeMotionTask);
  CHECK(task.type == TaskType::joint_waypoints);
  CHECK(task.end_time() == 8.0);
  Vec4 q, qd, qdd;
  task.trajectory.evaluate(2.0, q, qd, qdd);
  CHECK((q - Vec4(0.2, 2.60, 2.30, 1.95)).norm() < 1e-12);
}

TEST_CASE("firmware/task dig path: the tip follows the given poses through the model (sub-mm)") {
  const Task task = parse(sim::kDigTask);
  CHECK(task.type == TaskType::dig);
  const Model model = build_model(reference_machine());
  Workspace ws(model);
  for (const DigWaypoint& wp : task.path) {
    Vec4 q, qd, qdd;
    task.trajectory.evaluate(wp.t, q, qd, qdd);
    REQUIRE(update_closed_chain(model, ws, q, Vec4::Zero()).ok());
    CHECK(std::abs(ws.rho.x() - wp.pose.x) < 1e-4);
    CHECK(std::abs(ws.rho.y() - wp.pose.z) < 1e-4);
    CHECK(std::abs(ws.q[kBoom] + ws.q[kArm] + ws.q[kBucket] - wp.pose.pitch) < 1e-4);
  }
  // Between waypoints too (the joint spline through 10 ms IK samples stays on the tip path).
  Vec4 q, qd, qdd;
  task.trajectory.evaluate(5.005, q, qd, qdd);
  REQUIRE(update_closed_chain(model, ws, q, Vec4::Zero()).ok());
  CHECK(ws.rho.y() < -0.35);  // dragging ~0.4 m deep
}

TEST_CASE("firmware/task limits are rejected before the run with the waypoint named at its line") {
  // Waypoint 2 asks for a tip pose outside the bucket cylinder's stroke: named before the samples
  // between waypoints are checked.
  check_error(R"(
task:
  type: dig
  path:
    - {t: 0.0, x: 8.0, z: 0.6, pitch_deg: 20}
    - {t: 2.0, x: 7.8, z: 0.05, pitch_deg: 15}
    - {t: 4.0, x: 7.4, z: -0.4, pitch_deg: 60}
)",
              "task.path[2]", "{t: 4.0", "cylinder length would be");
  // Out of reach altogether.
  check_error(R"(
task:
  type: dig
  path:
    - {t: 0.0, x: 8.0, z: 0.6, pitch_deg: 20}
    - {t: 3.0, x: 8.5, z: 0.6, pitch_deg: 20}
    - {t: 6.0, x: 14.0, z: 0.6, pitch_deg: 20}
)",
              "task.path[2]", "{t: 6.0", "out of reach");
  // Too fast: the same drag in 0.3 s; the segment is named, the place is its first waypoint.
  check_error(R"(
task:
  type: dig
  path:
    - {t: 0.0, x: 7.4, z: -0.4, pitch_deg: 10}
    - {t: 0.3, x: 6.3, z: -0.45, pitch_deg: 5}
)",
              "task.path[0] -> task.path[1]", "{t: 0.0", "speed is");
  // A joint waypoint outside the boom stroke names the waypoint and the element.
  check_error(R"(
task:
  type: joint_waypoints
  waypoints:
    - {t: 0.0, q: [0.0, 2.45, 2.40, 2.10]}
    - {t: 2.0, q: [0.0, 3.10, 2.40, 2.10]}
)",
              "task.waypoints[1].q[1]", "3.10", "is 3.1; allowed range [1.7, 2.83]");
}

TEST_CASE("firmware/task schema errors name the field, its line and column and the allowed values") {
  check_error("task: {type: wiggle}", "task.type", "wiggle", "is 'wiggle'; allowed values: joint_waypoints, dig, truck_loading");
  check_error("task: {waypoints: []}", "task.type", "{waypoints", "missing; allowed values: joint_waypoints, dig, truck_loading");
  check_error("task: {type: dig, path: [{t: 0, x: 8, z: 0.6, pitch_deg: 60}]}", "task.path", "[{t: 0",
              "must be a list of 2..100000 entries");
  check_error("task: {type: dig, path: [{t: 0, x: 8, z: 0.6, pitch_deg: 60}, {t: 1, x: 8, z: 0.5, pitch_deg: 60, pitch: 6}]}",
              "task.path[1].pitch", "pitch: 6}", "unknown key; allowed keys: t, x, z, pitch_deg");
  // A misspelt required key is first a missing one, named at its mapping.
  check_error("task: {type: dig, path: [{t: 0, x: 8, z: 0.6, pitch_deg: 60}, {t: 1, x: 8, z: 0.5, pitch: 60}]}",
              "task.path[1].pitch_deg", "{t: 1", "missing: angle of M->L above swing x; a number in [-360, 360] deg");
  check_error("task: {type: joint_waypoints, waypoints: [{t: 1, q: [0, 2.45, 2.4, 2.1]}, {t: 1, q: [0, 2.45, 2.4, 2.2]}]}",
              "task.waypoints[1].t", "1, q: [0, 2.45, 2.4, 2.2]", "1 s must be later than the previous waypoint's 1 s");
  check_error("task: {type: joint_waypoints, waypoints: [{t: 0, q: [0, 2.45, 2.4]}, {t: 1, q: [0, 2.45, 2.4, 2.1]}]}",
              "task.waypoints[0].q", "[0, 2.45, 2.4]", "must be a list of 4 numbers");
  check_error("task: {type: joint_waypoints, waypoints: [{t: 0, q: [0, 2.45, abc, 2.1]}, {t: 1, q: [0, 2.45, 2.4, 2.1]}]}",
              "task.waypoints[0].q[2]", "abc", "'abc' is not a number; allowed range [2.11, 3.47]");
  check_error(std::string(sim::kDigTask) + "  return_time: 2\n  repeat: 0  # none\n", "task.repeat", "0  # none",
              "is 0; allowed: a whole number in [1, 1000]");
  check_error(std::string(sim::kDigTask) + "  efforts: {soil_margin: 2}\n", "task.efforts.soil_margin", "2}",
              "is 2; allowed range [0, 0.9]");
  check_error(std::string(sim::kDigTask) + "  efforts: {check: maybe}\n", "task.efforts.check", "maybe",
              "is 'maybe'; allowed values: true, false");
  // No task at all: placed at its section, the file's top, as the reader places every missing key.
  try {
    parse("other: 1");
    FAIL("no error");
  } catch (const SettingsError& e) {
    CHECK(e.file() == "scene.yaml");
    CHECK(e.field() == "task");
    CHECK(e.line() == 1);
    CHECK(e.reason() == "missing: the firmware needs a task (type: joint_waypoints, dig, truck_loading)");
  }
}
