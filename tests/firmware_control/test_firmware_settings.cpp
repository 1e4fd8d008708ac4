// The firmware's own loader of a scene file: its sections read, the plant's left alone, typos refused.
#include <doctest/doctest.h>

#include <cmath>
#include <yaml-cpp/yaml.h>

#include <string>

#include "app/firmware_node.hpp"
#include "app/firmware_settings.hpp"
#include "control/controller_registry.hpp"
#include "control/task/effort_feasibility.hpp"
#include "scenes.hpp"
#include "settings_error_check.hpp"
#include "model/machine_reader.hpp"
#include "settings/section_reader.hpp"

using namespace exc;

namespace {

const std::string kDig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";

app::FirmwareSettings read(const std::string& yaml) {
  return app::read_firmware_settings(settings::Document::parse(yaml, "scene.yaml"));
}

// A bad scene's error: scene.yaml, the field, the place where `at` begins, the reason part.
void check_error(const std::string& yaml, const std::string& field, const std::string& at, const std::string& reason) {
  CAPTURE(yaml);
  try {
    read(yaml);
    FAIL("no error");
  } catch (const SettingsError& e) {
    exc::test::check_settings_error(e, "scene.yaml", yaml, field, at, reason);
  }
}

const char* const kTask = R"(
task:
  type: joint_waypoints
  waypoints:
    - {t: 0.0, q: [0.0, 2.30, 2.60, 1.95]}
    - {t: 2.0, q: [0.1, 2.35, 2.65, 1.90]}
)";

}  // namespace

TEST_CASE("firmware/settings read the shipped dig scene's firmware sections as written in the file") {
  const app::FirmwareSettings s = app::load_firmware_settings(kDig);
  CHECK(s.name == "dig");
  CHECK(s.task.type == control::TaskType::dig);
  CHECK(s.task.path.size() == 6);           // six tip poses in the file
  CHECK(s.task.end_time() == doctest::Approx(10.0));
  CHECK(s.controller.command_interface == control::CommandInterface::valve);  // a hydraulic machine
  CHECK(s.controller.actuation.actuator_lag == 0.0);
  // Derived for the valves (no controller setting in the scene): eq. 27's rates at period / T_f of the
  // force-commanded defaults, the flow feedforward's position gain at 1 / (5 T_f), T_f the spools' lag.
  const double t_f = s.machine.hydraulics.valve_time_constant;
  CHECK(s.controller.actuation.valves.force_time_constant == t_f);
  CHECK(s.controller.adaptation.rate[2] == doctest::Approx(control::AdaptationSettings{}.rate[2] * 1e-3 / t_f));
  CHECK(s.controller.actuation.valves.position_gain[2] == doctest::Approx(1 / (5 * t_f)));
  CHECK(s.controller.adaptation.external_force.cutoff_hz == doctest::Approx(s.controller.filter.acceleration_cutoff_hz / 3));
  CHECK(s.duration == doctest::Approx(10.1));  // the path ends at 10.05 s
  CHECK(s.terrain.height == doctest::Approx(0.0));
  CHECK(s.machine_file.empty());  // no 'machine:' key: the built-in reference machine
  CHECK(s.machine.bodies.size() == reference_machine().bodies.size());
}

TEST_CASE("firmware/settings read the paper's force-actuated dig with the actuators' lag compensated") {
  const app::FirmwareSettings s = app::load_firmware_settings(std::string(EXC_SOURCE_DIR) + "/scenes/paper_dig.yaml");
  CHECK(s.name == "paper_dig");
  CHECK(s.controller.command_interface == control::CommandInterface::effort);
  CHECK(s.controller.actuation.actuator_lag == doctest::Approx(0.02));
}

TEST_CASE("firmware/settings refuse a flow law on the effort interface, naming both fields") {
  check_error("name: x\nduration: 2\ncontroller: {type: flow}\n" + std::string(kTask), "controller.type", "flow",
              "flow commands the valves' flow: it needs command_interface: valve");
  CHECK(read("name: x\nduration: 2\ncontroller: {type: flow, command_interface: valve}\n" + std::string(kTask))
            .controller.law == "flow");
}

// A law whose construction refuses its settings, as the adaptive law refuses gains whose Lyapunov
// equation has no positive definite solution: a swing position gain above 500 (a test law).
class PickyLaw final : public control::Controller {
 public:
  explicit PickyLaw(const control::ControllerConfig& c) {
    if (c.pid.gains.kp[0] > 500) throw SettingsError("", 0, 0, "controller.kp", "the picky law takes a swing gain of at most 500");
  }
  void reset() override {}
  control::ControlOutput update(const control::ControlInput&) override { return {}; }
};

TEST_CASE("firmware/settings name the file, line and key of a settings error only a law's construction finds") {
  static const bool registered = [] {
    control::register_controller({"picky", "refuses a swing gain above 500 when built (a test law)",
                                  control::build_law<PickyLaw>, control::kAnyInterface});
    return true;
  }();
  (void)registered;
  const std::string scene = "name: x\nduration: 2\ncontroller:\n  type: picky\n  kp: [600, 64, 64, 64]\n" + std::string(kTask);
  check_error(scene, "controller.kp", "[600", "the picky law cannot be built: the picky law takes a swing gain of at most 500");
  // Named or not, a law the scene may run is built: with no type, every law its interface carries.
  check_error("name: x\nduration: 2\ncontroller:\n  kp: [600, 64, 64, 64]\n" + std::string(kTask), "controller.kp", "[600",
              "the picky law cannot be built");
  // The control: within its range the scene reads.
  CHECK(read("name: x\nduration: 2\ncontroller:\n  type: picky\n  kp: [400, 64, 64, 64]\n" + std::string(kTask)).controller.law ==
        "picky");
}

TEST_CASE("firmware/settings derive the defaults a scene leaves out from the machine, the interface and the other settings, and keep what it gives") {
  // A slower spool on the nominal machine: the force loop takes its time constant, the spool lead
  // aims at a third of it (and the position gain and eq. 27's valve rates follow T_f, below).
  Machine slow = reference_machine();
  slow.hydraulics.valve_time_constant = 0.06;
  const control::ControllerConfig from_slow = control::controller_defaults(slow);
  CHECK(from_slow.actuation.valves.force_time_constant == 0.06);
  CHECK(from_slow.actuation.valves.spool_lag_target == doctest::Approx(0.02));
  const app::FirmwareSettings effort = read("name: x\nduration: 2\n" + std::string(kTask));
  const app::FirmwareSettings valve =
      read("name: x\nduration: 2\ncontroller: {command_interface: valve, valves: {force_time_constant: 0.05}}\n" +
           std::string(kTask));
  CHECK(effort.controller.adaptation.rate == control::AdaptationSettings{}.rate);  // the paper's rates
  CHECK(valve.controller.adaptation.rate[5] == doctest::Approx(control::AdaptationSettings{}.rate[5] * 1e-3 / 0.05));
  CHECK(valve.controller.actuation.valves.position_gain[1] == doctest::Approx(1 / (5 * 0.05)));
  // Given values are kept as given.
  const app::FirmwareSettings given = read(
      "name: x\nduration: 2\ncontroller: {command_interface: valve, adaptation_rate: [1, 2, 3, 4, 5, 6], valves: "
      "{position_gain: [1, 1, 1, 1]}, filters: {acceleration_cutoff_hz: 30}, external_force: {cutoff_hz: 4}}\n" +
      std::string(kTask));
  CHECK(given.controller.adaptation.rate[5] == 6);
  CHECK(given.controller.actuation.valves.position_gain[3] == 1);
  CHECK(given.controller.adaptation.external_force.cutoff_hz == 4);
  CHECK(read("name: x\nduration: 2\ncontroller: {filters: {acceleration_cutoff_hz: 30}}\n" + std::string(kTask))
            .controller.adaptation.external_force.cutoff_hz == doctest::Approx(10));
  // The effective configuration prints the derived values, so a run's dump says what it used.
  const YAML::Node dump = valve.effective["controller"];
  CHECK(dump["valves"]["position_gain"][0].as<double>() == doctest::Approx(4));
  CHECK(dump["adaptation_rate"][2].as<double>() == doctest::Approx(control::AdaptationSettings{}.rate[2] * 0.02));
  CHECK(dump["external_force"]["cutoff_hz"].as<double>() == doctest::Approx(5));
  // An observer cut-off at or above the acceleration filter's is refused at its place.
  check_error("name: x\nduration: 2\ncontroller: {external_force: {cutoff_hz: 15}}\n" + std::string(kTask),
              "controller.external_force.cutoff_hz", "15", "15 Hz must be below filters.acceleration_cutoff_hz = 15 Hz");
}

TEST_CASE("firmware/settings name a misspelt key in the plant's sections at its line, with the key it nearly spells, without reading their values") {
  const std::string top = "name: x\nduration: 2\n";
  check_error(top + "soil: {presett: loam}\n" + kTask, "soil.presett", "presett",
              "unknown key; did you mean preset? allowed keys: preset, stiffness, damping, mass");
  check_error(top + "integrator:\n  method: rk4\n  stepp: 0.0005\n" + kTask, "integrator.stepp", "stepp",
              "unknown key; did you mean step?");
  check_error(top + "sensors: {sead: 3}\n" + kTask, "sensors.sead", "sead", "unknown key; did you mean seed?");
  check_error(top + "checks: {energy_tolerence: 1}\n" + kTask, "checks.energy_tolerence", "energy_tolerence",
              "unknown key; did you mean energy_tolerance?");
  check_error(top + "initial_state: {qa: [0, 2.4, 2.5, 1.9]}\n" + kTask, "initial_state.qa", "qa",
              "unknown key; did you mean q_a?");
  check_error(top + "actuators: hydraulic\n" + kTask, "actuators", "hydraulic", "must be a mapping");
  // Their values are the plant's to check: a value out of the plant's range passes here.
  CHECK_NOTHROW(read(top + "soil: {preset: no_such_soil}\nintegrator: {step: -1}\n" + kTask));
}

TEST_CASE("firmware/settings accept the plant's sections without reading them and refuse unknown ones") {
  const std::string plant_sections =
      "name: x\nduration: 2\nsoil: {preset: loam}\nactuators: {fidelity: limited, lag: 0.02}\n"
      "integrator: {method: rk4}\nsensors: {seed: 3}\ninitial_state: {q_a: [0, 2.4, 2.5, 1.9]}\nchecks: {}\n";
  CHECK_NOTHROW(read(plant_sections + kTask));
  check_error("name: x\nduration: 2\nsoyl: {preset: loam}\n" + std::string(kTask), "soyl", "soyl",
              "unknown key; did you mean soil? allowed keys: name, description, machine, terrain, duration, controller, task, soil, "
              "initial_state, actuators, integrator, sensors, checks");
  check_error("name: x\nduration: 2\n", "task", "name: x", "missing: the firmware needs a task (type: joint_waypoints, dig, truck_loading)");
  check_error("name: x\n" + std::string(kTask), "duration", "name: x", "missing: how long the run lasts");
  // An unknown key spelt nearly as a declared one: named with it, as git and cargo do.
  check_error("name: x\nduration: 2\ntask_: {}\n" + std::string(kTask), "task_", "task_", "unknown key; did you mean task? allowed keys:");
  // A misspelt required key: the misspelling is named with the key it misses, not "duration: missing".
  check_error("name: x\ndurration: 2\n" + std::string(kTask), "durration", "durration",
              "unknown key; did you mean duration? (duration is required and not given) allowed keys:");
  check_error("name: x\nduration: 2\nterrain: {height: 50}\n" + std::string(kTask), "terrain.height", "50",
              "is 50 m; allowed range [-20, 20] m");
  check_error("name: x\nduration: 2\ncontroller: {kp: 3}\n" + std::string(kTask), "controller.kp", "3}",
              "must be a list of 4 numbers");
  check_error("name: x\nduration: 2\nmachine: /nonexistent.yaml\n" + std::string(kTask), "machine", "/nonexistent",
              "the machine file does not load: /nonexistent.yaml: cannot open the file");
}

TEST_CASE("firmware/settings name the file when it is missing or not YAML") {
  try {
    app::load_firmware_settings("/nonexistent/scene.yaml");
    FAIL("no error");
  } catch (const SettingsError& e) {
    CHECK(e.file() == "/nonexistent/scene.yaml");
    CHECK(e.line() == 0);
    CHECK(e.reason() == "cannot open the file");
  }
}

namespace {

// A saturating scene: a 2 rad swing in 2.5 s, inside the swing's speed limit but not its torque.
std::string fast_swing_scene(const std::string& efforts, const std::string& duration = "3") {
  std::string task = exc::control::sim::kFastSwingTask;
  const std::string type = "  type: joint_waypoints\n";
  task.insert(task.find(type) + type.size(), efforts);
  return "name: fast_swing\nduration: " + duration + "\n" + task;
}

}  // namespace

TEST_CASE("firmware/settings refuse a task the actuators cannot drive, naming the place, the joint, the torque and the timing that fits") {
  const std::string yaml = fast_swing_scene("");
  try {
    read(yaml);
    FAIL("no error");
  } catch (const SettingsError& e) {
    const std::string reason = e.reason();
    MESSAGE(reason);
    // The place: the task's waypoints, at their line.
    exc::test::check_settings_error(e, "scene.yaml", yaml, "task.waypoints", "- {t: 0.0", "task.waypoints[0] -> task.waypoints[1] at t = ");
    CHECK(reason.rfind("task.waypoints[0] -> task.waypoints[1] at t = ", 0) == 0);
    CHECK(reason.find("the swing needs ") != std::string::npos);
    CHECK(reason.find("65.0 kN m") != std::string::npos);
    CHECK(reason.find("it fits with the timing scaled by 2.2") != std::string::npos);
    CHECK(reason.find("or set task.efforts.fit_timing: true") != std::string::npos);
  }
}

TEST_CASE("firmware/settings fit a task's timing when asked, say by how much and stretch the run's duration with it, check: false forces it as written") {
  const app::FirmwareSettings fit =
      read(fast_swing_scene("  efforts: {fit_timing: true}\n"));
  MESSAGE("timing scaled by " << fit.task.timing_scale);
  CHECK(fit.task.timing_scale > 2.0);
  CHECK(fit.task.timing_scale < 2.5);
  CHECK(fit.task.end_time() == doctest::Approx(2.5 * fit.task.timing_scale));
  CHECK(fit.task.waypoint_times.back() == doctest::Approx(2.5 * fit.task.timing_scale));
  const Model model = build_model(fit.machine);
  CHECK(control::check_effort_feasibility(model, fit.task.trajectory).ok);
  // The 3 s run covered the 2.5 s path: it covers the stretched path and the 0.5 s after it.
  CHECK(fit.scene_duration == 3);
  // In whole cycles, rounded up: the run steps by them.
  const auto whole_cycles = [](double seconds) { return 1e-3 * std::ceil(seconds / 1e-3 - 1e-9); };
  CHECK(fit.duration == doctest::Approx(whole_cycles(2.5 * fit.task.timing_scale + 0.5)).epsilon(1e-12));
  CHECK(std::abs(fit.duration / 1e-3 - std::round(fit.duration / 1e-3)) < 1e-9);
  // Covered to its last cycle, it still runs until the task has finished (tracking from 50 ms on).
  const app::FirmwareSettings exact = read(fast_swing_scene("  efforts: {fit_timing: true}\n", "2.5"));
  CHECK(exact.duration ==
        doctest::Approx(whole_cycles(2.5 * exact.task.timing_scale + app::FirmwareNodeConfig{}.track_delay + 1e-3)).epsilon(1e-12));
  // A run asked for part of the path keeps its duration.
  CHECK(read(fast_swing_scene("  efforts: {fit_timing: true}\n", "2")).duration == 2);

  const app::FirmwareSettings forced =
      read(fast_swing_scene("  efforts: {check: false}\n"));
  CHECK(forced.task.timing_scale == 1.0);
  CHECK(forced.task.end_time() == doctest::Approx(2.5));
  CHECK(forced.duration == 3);
  const std::string maybe = fast_swing_scene("  efforts: {check: maybe}\n");
  check_error(maybe, "task.efforts.check", "maybe", "is 'maybe'; allowed values: true, false");
}

TEST_CASE("firmware/settings accept a run of a working shift (duration 28800 s) and refuse one second more, naming the field and the range") {
  CHECK(read("name: x\nduration: 28800\n" + std::string(kTask)).duration == 28800);
  check_error("name: x\nduration: 28801\n" + std::string(kTask), "duration", "28801",
              "is 28801 s; allowed range [0.001, 28800] s");
}

TEST_CASE("firmware/settings name a required key's misspelling only once the section's keys are all declared") {
  double q = 0, qd = 0, w = 0;
  const auto read_q = [&](const std::string& yaml) {
    settings::SectionReader r("f.yaml", "", YAML::Load(yaml));
    r.number("q_a", q, {-10, 10}, "m", "the required one", settings::Need::required);
    r.number("qd_a", qd, {-10, 10}, "m/s", "an optional one declared later");
    r.number("w", w, {0, 1}, "", "another optional one");
    r.finish();
  };
  const auto error_of = [&](const std::string& yaml) {
    try {
      read_q(yaml);
    } catch (const SettingsError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // qd_a is spelt nearly as q_a but is a field of its own: q_a is plainly missing.
  CHECK(error_of("qd_a: 1\n") == "f.yaml:1:1: q_a: missing: the required one; a number in [-10, 10] m");
  // q_b is no field: it is named, with the required key it misspells.
  CHECK(error_of("q_b: 1\nqd_a: 1\n") ==
        "f.yaml:1:1: q_b: unknown key; did you mean q_a? (q_a is required and not given) allowed keys: q_a, qd_a, w");
  // Another error of the section read after the missing key still reports the missing key first.
  CHECK(error_of("q_b: 1\nw: 5\n").find("q_a: missing") != std::string::npos);
  CHECK(error_of("q_a: 1\n") == "no error");
}
