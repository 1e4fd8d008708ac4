// "One file to add a thing": a control law defined here, in this file alone, registered
// with one call, then named by a scene's controller.type and run the way excavator-sim runs a scene
// (scene reader, firmware node and hydraulic plant in lockstep over the in-memory bus). Its commands
// must reach the machine: the law asks the arm's valve for a constant flow and nothing else, the task
// holds still, so the arm must extend at that speed and the other functions stay where they are.
#include <doctest/doctest.h>

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "app/firmware_node.hpp"
#include "control/controller_registry.hpp"
#include "harness/lockstep_run.hpp"
#include "harness/scene_source.hpp"
#include "report/in_process_run.hpp"
#include "scratch_files.hpp"
#include "sim_plant/plant.hpp"

using namespace exc;

namespace {

constexpr double kArmSpeed = 0.02;  // m/s the law asks of the arm cylinder

// The law: the arm's valve passes kArmSpeed, every other valve stays centred. A flow law, so the
// valve interface alone can carry it.
class ArmCreep final : public control::Controller {
 public:
  explicit ArmCreep(const control::ControllerConfig&) {}
  void reset() override {}
  control::ControlOutput update(const control::ControlInput& in) override {
    control::ControlOutput out;
    out.e = in.q - in.q_d;
    out.ed = in.qd - in.qd_d;
    out.velocity_command = true;
    out.velocity = Vec4(0, 0, kArmSpeed, 0);
    return out;
  }
};

void register_arm_creep_once() {
  static const bool registered = [] {
    control::register_controller({"arm_creep", "the arm's valve at a constant flow, the rest centred (a test law)",
                                  control::build_law<ArmCreep>, control::kValveInterface});
    return true;
  }();
  (void)registered;
}

// A valve-commanded scene on the hydraulic machine whose task holds the first pose of scenes/dig.yaml.
std::string scene_text(const std::string& controller_type, const std::string& interface, const std::string& fidelity) {
  return "name: registry\n"
         "terrain: {height: 0.0}\n"
         "soil: {preset: none}\n"
         "initial_state: {q_a: [0.0, 2.5021, 2.9255, 1.7856], qd_a: [0, 0, 0, 0]}\n"
         "actuators: {fidelity: " + fidelity + "}\n"
         "integrator: {method: semi_implicit_euler, formulation: independent, step: 0.001}\n"
         "duration: 2\n"
         "sensors: {seed: 1}\n"
         "controller: {type: " + controller_type + ", command_interface: " + interface + "}\n"
         "task:\n"
         "  type: joint_waypoints\n"
         "  waypoints:\n"
         "    - {t: 0.0, q: [0.0, 2.5021, 2.9255, 1.7856]}\n"
         "    - {t: 5.0, q: [0.0, 2.5021, 2.9255, 1.7856]}\n";
}

std::string write_scene(const std::string& name, const std::string& text) {
  static const std::filesystem::path dir =
      test::scratch_dir(std::filesystem::temp_directory_path() / ("exc-registry-" + std::to_string(::getpid())));
  const std::filesystem::path path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

}  // namespace

TEST_CASE("firmware/registry: a law registered in one call is named by a scene's controller.type, run in lockstep, and its valve flow moves the machine") {
  register_arm_creep_once();
  const sim::SceneBundle bundle =
      sim::load_scene_bundle(write_scene("creep.yaml", scene_text("arm_creep", "valve", "hydraulic")));
  REQUIRE(bundle.firmware.controller.law_given);
  CHECK(bundle.firmware.controller.law == "arm_creep");
  // The programs' --controller check and --help read the same registry.
  CHECK_NOTHROW(sim::check_controller_names({"arm_creep", "pid"}));
  CHECK(control::controller_registry().help().find("arm_creep: the arm's valve at a constant flow") != std::string::npos);

  sim::LockstepOptions o;
  o.controller = bundle.firmware.controller.law;
  double track_start = -1, arm_at_start = 0;
  Vec4 q_first = Vec4::Zero(), q_last = Vec4::Zero();
  bool first = true;
  o.observer = [&](std::int64_t cycle, const plant::Plant& plant, const app::FirmwareNode& firmware) {
    const Vec4& q = plant.state().q_a;
    if (first) q_first = q;
    first = false;
    if (track_start < 0 && firmware.tracking()) {
      track_start = static_cast<double>(cycle + 1) * bundle.scene.cycle;
      arm_at_start = q[2];
    }
    q_last = q;
  };
  const sim::RunRecord r = sim::run_lockstep(bundle.scene, bundle.firmware, o);
  INFO(r.failure);
  REQUIRE(r.ok);
  CHECK(r.controller == "arm_creep");
  REQUIRE(track_start >= 0);
  // The arm extends at the asked speed from the first tracking cycle (10 % for the valve's lag and
  // the orifice map's model of the flow); the centred valves hold the others (the machine's
  // load-holding: well under a millimetre and a milliradian).
  const double asked = kArmSpeed * (r.simulated_seconds - track_start);
  MESSAGE("arm moved " << (q_last[2] - arm_at_start) * 1e3 << " mm, asked " << asked * 1e3 << " mm");
  CHECK(q_last[2] - arm_at_start == doctest::Approx(asked).epsilon(0.1));
  CHECK(std::abs(q_last[0] - q_first[0]) < 1e-3);
  CHECK(std::abs(q_last[1] - q_first[1]) < 1e-3);
  CHECK(std::abs(q_last[3] - q_first[3]) < 1e-3);
}

TEST_CASE("firmware/registry: an unknown controller.type is refused with every registered name, the added law's among them, and the added law's interface rule holds") {
  register_arm_creep_once();
  const std::string unknown = write_scene("unknown.yaml", scene_text("arm_crept", "valve", "hydraulic"));
  CHECK_THROWS_WITH_AS(sim::load_scene_bundle(unknown), doctest::Contains("allowed values: pid, adaptive, slotine_li, flow, arm_creep"),
                       settings::SettingsError);
  CHECK_THROWS_WITH_AS(sim::check_controller_names({"arm_crept"}), doctest::Contains("arm_creep"), std::invalid_argument);
  // A flow law on force-commanded actuators: refused by the rule its entry declares, at the field.
  const std::string effort = write_scene("effort.yaml", scene_text("arm_creep", "effort", "ideal"));
  CHECK_THROWS_WITH_AS(sim::load_scene_bundle(effort),
                       doctest::Contains("arm_creep commands the valves' flow: it needs command_interface: valve"),
                       settings::SettingsError);
  // A name is taken once.
  CHECK_THROWS_AS(control::register_controller({"arm_creep", "again", control::build_law<ArmCreep>}), std::invalid_argument);
}
