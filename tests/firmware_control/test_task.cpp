#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>

#include "control/task.hpp"
#include "model/closed_chain.hpp"
#include "scenes.hpp"

using namespace exc;
using namespace exc::control;

namespace {

Task parse(const std::string& yaml) {
  return parse_task(YAML::Load(yaml)["task"], "scene.yaml", reference_machine());
}

// The error a bad task gives, as "field | reason".
std::string error_of(const std::string& yaml) {
  try {
    parse(yaml);
  } catch (const ConfigError& e) {
    CHECK(e.file() == "scene.yaml");
    return e.field() + " | " + e.reason();
  }
  return "no error";
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

TEST_CASE("firmware/task limits are rejected before the run with the waypoint named") {
  // Waypoint 2 asks for a tip pose outside the bucket cylinder's stroke: named before the samples
  // between waypoints are checked.
  const std::string bad_stroke = R"(
task:
  type: dig
  path:
    - {t: 0.0, x: 8.0, z: 0.6, pitch_deg: 20}
    - {t: 2.0, x: 7.8, z: 0.05, pitch_deg: 15}
    - {t: 4.0, x: 7.4, z: -0.4, pitch_deg: 60}
)";
  const std::string e1 = error_of(bad_stroke);
  CHECK_MESSAGE(e1.find("task.path[2]") == 0, e1);
  CHECK_MESSAGE(e1.find("outside the allowed") != std::string::npos, e1);
  // Out of reach altogether.
  const std::string e2 = error_of(R"(
task:
  type: dig
  path:
    - {t: 0.0, x: 8.0, z: 0.6, pitch_deg: 20}
    - {t: 3.0, x: 8.5, z: 0.6, pitch_deg: 20}
    - {t: 6.0, x: 14.0, z: 0.6, pitch_deg: 20}
)");
  CHECK_MESSAGE(e2.find("task.path[2] |") == 0, e2);
  CHECK_MESSAGE(e2.find("out of reach") != std::string::npos, e2);
  // Too fast: the same drag in 0.3 s.
  const std::string e3 = error_of(R"(
task:
  type: dig
  path:
    - {t: 0.0, x: 7.4, z: -0.4, pitch_deg: 10}
    - {t: 0.3, x: 6.3, z: -0.45, pitch_deg: 5}
)");
  CHECK_MESSAGE(e3.find("speed") != std::string::npos, e3);
  // A joint waypoint outside the boom stroke names the waypoint and the element.
  const std::string e4 = error_of(R"(
task:
  type: joint_waypoints
  waypoints:
    - {t: 0.0, q: [0.0, 2.45, 2.40, 2.10]}
    - {t: 2.0, q: [0.0, 3.10, 2.40, 2.10]}
)");
  CHECK_MESSAGE(e4.find("task.waypoints[1].q[1]") == 0, e4);
  CHECK_MESSAGE(e4.find("1.7 .. 2.83") != std::string::npos, e4);
}

TEST_CASE("firmware/task schema errors name the field and the allowed values") {
  CHECK(error_of("task: {type: wiggle}").find("task.type | 'wiggle' (allowed: joint_waypoints, dig, truck_loading)") == 0);
  CHECK(error_of("other: 1").find("task | missing") == 0);
  CHECK(error_of("task: {type: dig, path: [{t: 0, x: 8, z: 0.6, pitch_deg: 60}]}").find("task.path | must be a list of at least 2") == 0);
  CHECK(error_of("task: {type: dig, path: [{t: 0, x: 8, z: 0.6, pitch_deg: 60}, {t: 1, x: 8, z: 0.5, pitch: 60}]}")
            .find("task.path[1].pitch | unknown key") == 0);
  CHECK(error_of("task: {type: joint_waypoints, waypoints: [{t: 1, q: [0, 2.45, 2.4, 2.1]}, {t: 1, q: [0, 2.45, 2.4, 2.1]}]}")
            .find("task.waypoints[1].t | 1 s must be later") == 0);
  CHECK(error_of("task: {type: joint_waypoints, waypoints: [{t: 0, q: [0, 2.45, 2.4]}, {t: 1, q: [0, 2.45, 2.4, 2.1]}]}")
            .find("task.waypoints[0].q | must be 4 numbers") == 0);
  CHECK(error_of("task: {type: joint_waypoints, waypoints: [{t: 0, q: [0, 2.45, abc, 2.1]}, {t: 1, q: [0, 2.45, 2.4, 2.1]}]}")
            .find("task.waypoints[0].q[2] | not a number") == 0);
}
