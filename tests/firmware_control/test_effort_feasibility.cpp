// Effort feasibility before the run: the too-fast swing is refused with the swing named,
// the closed-form time scale is checked against inverse dynamics run on the rescaled path, and the
// shipped tasks pass.
#include <doctest/doctest.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <string>

#include "app/firmware_settings.hpp"
#include "control/task/effort_feasibility.hpp"
#include "control/task/task.hpp"
#include "model/actuator_friction.hpp"
#include "model/closed_chain.hpp"
#include "model/workspace.hpp"
#include "scenes.hpp"
#include "model/machine_reader.hpp"
#include "control/task/task_reader.hpp"

using namespace exc;
using namespace exc::control;

namespace {

// The largest |tau_j| / limit_j along a trajectory, by plain inverse dynamics every 0.5 ms.
double worst_load(const Model& model, const JointTrajectory& tr, int joint) {
  Workspace ws(model);
  double worst = 0;
  Vec4 q, qd, qdd, tau;
  for (double t = tr.start_time(); t <= tr.end_time(); t += 5e-4) {
    tr.evaluate(t, q, qd, qdd);
    REQUIRE(update_closed_chain(model, ws, q, qd).ok());
    inverse_dynamics(model, ws, qdd, Vec2::Zero(), tau);
    const double limit = tau[joint] >= 0 ? model.machine.effort_max()[joint] : model.machine.effort_min()[joint];
    worst = std::max(worst, tau[joint] / limit);
  }
  return worst;
}

}  // namespace

TEST_CASE("firmware/feasibility refuses a 2 rad swing in 2.5 s, naming the swing, its torque and the timing that fits") {
  const Model model = build_model(reference_machine());
  const Task task = read_task(settings::Document::parse(sim::kFastSwingTask, "scene.yaml"), model.machine);
  const FeasibilityReport r = check_effort_feasibility(model, task.trajectory);
  CHECK_FALSE(r.ok);
  CHECK(r.joint == 0);
  CHECK(std::abs(r.effort) > model.machine.swing.max_torque);
  CHECK(r.time_scale > 1);
  const std::string m = r.message(task.waypoint_times, "task.waypoints");
  MESSAGE(m);
  CHECK(m.find("task.waypoints[0] -> task.waypoints[1]") == 0);
  CHECK(m.find("the swing needs ") != std::string::npos);
  // Signed: accelerating needs +, braking - (equal in size for this symmetric move).
  CHECK((m.find("kN m, its limit is 65.0 kN m") != std::string::npos ||
         m.find("kN m, its limit is -65.0 kN m") != std::string::npos));
  CHECK(m.find("fits with the timing scaled by") != std::string::npos);
  // Independent evidence: plain inverse dynamics on the path as given exceeds the limit by the
  // reported factor (tau - g scales with 1/s^2; the swing has no gravity load).
  CHECK(worst_load(model, task.trajectory, 0) == doctest::Approx(r.time_scale * r.time_scale).epsilon(0.01));
}

TEST_CASE("firmware/feasibility's time scale is exact: the rescaled path touches the limit and stays within it") {
  const Model model = build_model(reference_machine());
  const Task task = read_task(settings::Document::parse(sim::kFastSwingTask, "scene.yaml"), model.machine);
  const double s = check_effort_feasibility(model, task.trajectory).time_scale;
  const JointTrajectory fit = scale_timing(task.trajectory, s * 1.001);
  const JointTrajectory tight = scale_timing(task.trajectory, s * 0.97);
  CHECK(check_effort_feasibility(model, fit).ok);
  CHECK_FALSE(check_effort_feasibility(model, tight).ok);
  // Run directly on the rescaled splines (not through the closed form): at the limit, not over it.
  const double at_fit = worst_load(model, fit, 0);
  CHECK(at_fit <= 1.0);
  CHECK(at_fit > 0.99);
  CHECK(worst_load(model, tight, 0) > 1.0);
  CHECK(fit.end_time() == doctest::Approx(2.5 * s * 1.001));
}

TEST_CASE("firmware/feasibility passes the shipped scenes' tasks and the test tasks") {
  const Model model = build_model(reference_machine());
  for (const char* scene : {"dig.yaml", "free_motion.yaml", "paper_dig.yaml", "paper_free_motion.yaml", "truck_loading.yaml"}) {
    const app::FirmwareSettings st = app::load_firmware_settings(std::string(EXC_SOURCE_DIR) + "/scenes/" + scene);
    FeasibilityOptions o;
    o.terrain = st.terrain;
    const FeasibilityReport r = check_effort_feasibility(build_model(st.machine), st.task.trajectory, o);
    INFO(scene << ": " << r.message(st.task.waypoint_times, "task"));
    CHECK(r.ok);
    CHECK(r.samples >= st.task.end_time() / 1e-3);
  }
  for (const char* yaml : {sim::kDigTask, sim::kFreeMotionTask}) {
    const Task task = read_task(settings::Document::parse(yaml, "test"), model.machine);
    CHECK(check_effort_feasibility(model, task.trajectory).ok);
  }
}

TEST_CASE("firmware/feasibility says no timing fits where gravity alone exceeds a limit") {
  Machine weak = reference_machine();
  weak.boom.max_force *= 0.02;  // far below the boom's static load
  weak.boom.min_force *= 0.02;
  const Model model = build_model(weak);
  const Task task = read_task(settings::Document::parse(sim::kFreeMotionTask, "test"), weak);
  const FeasibilityReport r = check_effort_feasibility(model, task.trajectory);
  CHECK_FALSE(r.ok);
  CHECK(std::isinf(r.time_scale));
  CHECK(r.joint == 1);
  CHECK(r.message(task.waypoint_times, "task.waypoints").find("no timing fits") != std::string::npos);
}

TEST_CASE("firmware/feasibility counts the actuators' dry friction against their limits: the swing's time scale grows as the limit less the friction") {
  const Model model = build_model(reference_machine());
  const Task task = read_task(settings::Document::parse(sim::kFastSwingTask, "scene.yaml"), model.machine);
  const double s0 = check_effort_feasibility(model, task.trajectory).time_scale;
  FeasibilityOptions o;
  const double limit = model.machine.effort_max()[0];
  o.friction[0] = 0.2 * limit;
  const FeasibilityReport r = check_effort_feasibility(model, task.trajectory, o);
  // No gravity on the swing: what the path needs scales with 1/s^2, so (s / s0)^2 = limit / (limit - F).
  CHECK(r.time_scale * r.time_scale == doctest::Approx(s0 * s0 / 0.8).epsilon(1e-3));
  CHECK(r.limit == doctest::Approx(std::copysign(0.8 * limit, r.limit)).epsilon(1e-9));
  // The hydraulic machine's own: the swing motor's breakaway takes a twelfth of its torque or more.
  const Vec4 f = coulomb_level(actuator_friction(model.machine), Vec4::Constant(model.machine.hydraulics.main_relief_pressure),
                               Vec4::Zero());
  CHECK(f[0] > limit / 12);
  CHECK(f[0] < limit / 4);
}
