// Scene validation: every error names the file, the field and the allowed values; the shipped scenes
// load.
#include <doctest/doctest.h>

#include <map>
#include <set>
#include <string>

#include "model/plant_scene_keys.hpp"
#include "model/scene_common.hpp"
#include "plant_scenes.hpp"
#include "settings_error_check.hpp"

using namespace exc;
using namespace exc::plant;

namespace {

const std::string kBase = "name: t\nduration: 1\ninitial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n";

}  // namespace

TEST_CASE("plant/scene minimal file loads with the documented defaults") {
  const Scene s = read_scene(settings::Document::parse(kBase, "ok.yaml"));
  CHECK(s.name == "t");
  CHECK(s.actuators.fidelity == "ideal");
  CHECK(s.integrator.method == "semi_implicit_euler");
  CHECK(s.integrator.formulation == Formulation::independent);
  CHECK(s.integrator.step == 1e-3);
  CHECK(s.cycle == 1e-3);
  CHECK(s.soil.stiffness.norm() == 0);
  CHECK(s.machine.name == "reference-20t");
}

TEST_CASE("plant/scene errors name the file, the line and column, the field and the allowed values") {
  struct Case {
    std::string yaml, field, at, reason;  // at: the text the error must point at
  };
  const std::string top_keys =
      "unknown key; allowed keys: name, description, machine, terrain, duration, soil, initial_state, actuators, "
      "integrator, sensors, checks, controller, task";
  const Case cases[] = {
      {kBase + "colour: red\n", "colour", "colour", top_keys},
      {kBase + "integrator: {method: leapfrog}\n", "integrator.method", "leapfrog",
       "is 'leapfrog'; allowed values: semi_implicit_euler, rk4, implicit_midpoint"},
      {kBase + "integrator: {formulation: lagrange}\n", "integrator.formulation", "lagrange",
       "is 'lagrange'; allowed values: independent, augmented_baumgarte, augmented_projection"},
      {kBase + "integrator: {step: 0.0003}\n", "integrator.step", "0.0003",
       "is 0.0003 s; must divide integrator.cycle (0.001 s) a whole number of times"},
      {kBase + "integrator: {step: -1}\n", "integrator.step", "-1", "is -1 s; allowed range [1e-06, 1] s"},
      {kBase + "integrator: {implicit_max_iterations: 2.5}\n", "integrator.implicit_max_iterations", "2.5",
       "is 2.5; allowed: a whole number in [1, 100]"},
      {kBase + "actuators: {fidelity: magic}\n", "actuators.fidelity", "magic",
       "is 'magic'; allowed values: ideal, limited, hydraulic"},
      {kBase + "actuators: {lag: 0.1, colour: 1}\n", "actuators.colour", "colour", "unknown key; allowed keys: fidelity, lag"},
      // The hydraulic machine's numbers are the machine file's now.
      {kBase + "actuators: {bulk_modulus: 1e9}\n", "actuators.bulk_modulus", "bulk_modulus",
       "unknown key; allowed keys: fidelity, lag"},
      {kBase + "soil: {preset: granite}\n", "soil.preset", "granite",
       "is 'granite'; allowed values: none, loose_sand, loam, stiff_clay"},
      {kBase + "soil: {preset: loam, stiffness: [1, 1]}\n", "soil.preset", "loam", "give either 'preset' or stiffness/damping/mass, not both"},
      {kBase + "soil: {stiffness: [1e5, 1e5], damping: [1, 1]}\n", "soil.mass", "{stiffness",
       "missing: M_t on x and z; a list of 2 numbers in [0, 10000] kg"},
      {kBase + "soil: {stiffness: [1e5], damping: [1, 1], mass: [1, 1]}\n", "soil.stiffness", "[1e5]",
       "must be a list of 2 numbers in [0, 1e+09] N/m"},
      {kBase + "terrain: {profile: [[0, 0], [0, 1]]}\n", "terrain.profile[1]", "[0, 1]]", "x must increase strictly"},
      {kBase + "terrain: {height: 0, profile: [[0, 0], [1, 1]]}\n", "terrain.profile", "[[0, 0]", "not both"},
      {kBase + "terrain: {height: 21}\n", "terrain.height", "21", "is 21 m; allowed range [-20, 20] m"},
      {kBase + "sensors: {latency_cycles: 100}\n", "sensors.latency_cycles", "100", "is 100; allowed: a whole number in [0, 63]"},
      {kBase + "sensors: {latency_cycles: 1.5}\n", "sensors.latency_cycles", "1.5", "is 1.5; allowed: a whole number in [0, 63]"},
      {kBase + "sensors: {position_noise: [0, 0, x, 0]}\n", "sensors.position_noise[2]", "x, 0]",
       "'x' is not a number; allowed range [0, 0.1]"},
      {kBase + "checks: {constraint_tolerance: 0}\n", "checks.constraint_tolerance", "0}", "is 0 m; allowed range [1e-12, 1] m"},
      {kBase + "checks: {pressure_check_margin: 6e7}\n", "checks.pressure_check_margin", "6e7",
       "is 6e+07 Pa; allowed range [0, 5e+07] Pa"},
      {"name: t\nduration: 1\ninitial_state: {q_a: [0, 3.5, 2.3, 2.1]}\n", "initial_state.q_a[1]", "3.5",
       "is 3.5; allowed range [1.7, 2.83]"},
      {"name: t\nduration: 1\ninitial_state: {qd_a: [0, 0.5, 0, 0]}\n", "initial_state.q_a", "{qd_a", "missing"},
      // Absent sections and keys are named at the nearest enclosing one in the file.
      {"name: t\nduration: 1\n", "initial_state.q_a", "name: t", "missing: [swing rad, L_boom, L_arm, L_bucket m]"},
      {"duration: 1\ninitial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n", "name", "duration", "missing: the scene's name; a string"},
      {"name: t\ninitial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n", "duration", "name",
       "missing: how long the run lasts (up to a working shift); a number in [0.001, 28800] s"},
      {kBase + "duration: 2\n", "duration", "duration: 2", "given twice in this mapping"},
      {kBase + "machine: no/such/machine.yaml\n", "machine", "no/such", "the machine file does not load: "},
      {kBase + "integrator: [1, 2]\n", "integrator", "[1, 2]", "must be a mapping"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.yaml);
    try {
      read_scene(settings::Document::parse(c.yaml, "bad.yaml"));
      FAIL("no error");
    } catch (const SettingsError& e) {
      exc::test::check_settings_error(e, "bad.yaml", c.yaml, c.field, c.at, c.reason);
    }
  }
}

TEST_CASE("plant/scene: a file that is not YAML is named with the line where the parser stopped") {
  try {
    read_scene(settings::Document::parse(kBase + "integrator: {method: rk4\n", "bad.yaml"));
    FAIL("no error");
  } catch (const SettingsError& e) {
    CHECK(e.file() == "bad.yaml");
    CHECK(e.field().empty());
    CHECK(e.line() == 5);  // the end of the file, where the mapping should have closed
    CHECK(e.reason().rfind("not valid YAML: ", 0) == 0);
  }
}

TEST_CASE("plant/scene leaves the firmware's controller and task sections to the firmware") {
  const Scene s = read_scene(settings::Document::parse(kBase + "controller: {anything: [1, 2]}\ntask: {type: whatever, x: 1}\n", "ok.yaml"));
  CHECK(s.has_controller);
  CHECK(s.has_task);
  CHECK_FALSE(s.effective["controller"].IsDefined());
  CHECK_FALSE(s.effective["task"].IsDefined());
  CHECK(s.effective["integrator"]["method"].as<std::string>() == "semi_implicit_euler");
}

TEST_CASE("plant/the plant's scene reader declares exactly the shared list of its keys, by which the firmware names a misspelt one") {
  // Every key the reader declares, section by section: the effective tree holds each key read (a
  // default filled in when absent); soil's two branches (a preset or explicit K, B, M) read apart.
  const std::string explicit_soil = "soil: {stiffness: [1, 1], damping: [1, 1], mass: [1, 1]}\n";
  std::map<std::string, std::set<std::string>> read;
  for (const std::string& yaml : {kBase, kBase + explicit_soil}) {
    const Scene s = read_scene(settings::Document::parse(yaml, "ok.yaml"));
    for (const std::string& section : kPlantSceneSections) {
      REQUIRE_MESSAGE(s.effective[section].IsMap(), section);
      for (const auto& kv : s.effective[section]) read[section].insert(kv.first.Scalar());
    }
  }
  REQUIRE(plant_scene_keys().size() == kPlantSceneSections.size());
  for (std::size_t i = 0; i < kPlantSceneSections.size(); ++i) {
    const SceneSectionKeys& listed = plant_scene_keys()[i];
    CAPTURE(listed.section);
    CHECK(listed.section == kPlantSceneSections[i]);
    CHECK(std::set<std::string>(listed.keys.begin(), listed.keys.end()) == read[listed.section]);
    CHECK(listed.keys.size() == read[listed.section].size());  // none listed twice
  }
}

TEST_CASE("plant/scene shipped scenes load and their initial states assemble") {
  for (const char* name : {"free_motion.yaml", "dig.yaml", "paper_free_motion.yaml", "paper_dig.yaml", "truck_loading.yaml"}) {
    CAPTURE(std::string(name));
    const Scene s = load_scene(std::string(EXC_SOURCE_DIR) + "/scenes/" + name);
    CHECK(s.has_task);
    Plant p(s);
    CHECK(p.status().ok());
    CHECK(p.state().q_a.isApprox(s.q_a0));
  }
  // The dig scene starts above the ground and has soil.
  const Scene dig = load_scene(std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml");
  CHECK(dig.soil.stiffness.minCoeff() > 0);
  Plant p(dig);
  CHECK_FALSE(p.state().in_soil);
}

TEST_CASE("plant/scene accepts a run of a working shift (duration 28800 s) and refuses one second more, naming the field and the range") {
  const std::string task = "initial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n";
  CHECK(read_scene(settings::Document::parse("name: t\nduration: 28800\n" + task, "ok.yaml")).duration == 28800);
  const std::string yaml = "name: t\nduration: 28801\n" + task;
  try {
    read_scene(settings::Document::parse(yaml, "bad.yaml"));
    FAIL("no error");
  } catch (const SettingsError& e) {
    exc::test::check_settings_error(e, "bad.yaml", yaml, "duration", "28801", "is 28801 s; allowed range [0.001, 28800] s");
  }
}
