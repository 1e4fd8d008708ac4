// Scene validation: every error names the file, the field and the allowed values; the shipped scenes
// load.
#include <doctest/doctest.h>

#include <string>

#include "plant_scenes.hpp"

using namespace exc;
using namespace exc::plant;

namespace {

// Loads 'yaml' and returns the error text (empty if it loaded).
std::string error_of(const std::string& yaml) {
  try {
    load_scene_from_string(yaml, "bad.yaml");
  } catch (const SceneError& e) {
    CHECK(e.file() == "bad.yaml");
    return std::string(e.what());
  }
  return "";
}

const std::string kBase = "name: t\nduration: 1\ninitial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n";

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("plant/scene minimal file loads with the documented defaults") {
  const Scene s = load_scene_from_string(kBase, "ok.yaml");
  CHECK(s.name == "t");
  CHECK(s.actuators.fidelity == ActuatorFidelity::ideal);
  CHECK(s.integrator.method == IntegrationMethod::semi_implicit_euler);
  CHECK(s.integrator.formulation == Formulation::independent);
  CHECK(s.integrator.step == 1e-3);
  CHECK(s.cycle == 1e-3);
  CHECK(s.soil.stiffness.norm() == 0);
  CHECK(s.machine.name == "reference-20t");
}

TEST_CASE("plant/scene errors name file, field and allowed values") {
  struct Case {
    std::string yaml, field, allowed;
  };
  const Case cases[] = {
      {kBase + "colour: red\n", "colour", "allowed keys: name, description"},
      {kBase + "integrator: {method: leapfrog}\n", "integrator.method", "semi_implicit_euler, rk4, implicit_midpoint"},
      {kBase + "integrator: {formulation: lagrange}\n", "integrator.formulation", "augmented_projection"},
      {kBase + "integrator: {step: 0.0003}\n", "integrator.step", "must divide integrator.cycle"},
      {kBase + "integrator: {step: -1}\n", "integrator.step", "allowed range"},
      {kBase + "actuators: {fidelity: magic}\n", "actuators.fidelity", "ideal, limited, hydraulic"},
      {kBase + "actuators: {bulk_modulus: 1}\n", "actuators.bulk_modulus", "[1e+07, 5e+09]"},
      {kBase + "actuators: {lag: 0.1, colour: 1}\n", "actuators.colour", "allowed keys: fidelity"},
      {kBase + "soil: {preset: granite}\n", "soil.preset", "loose_sand, loam, stiff_clay"},
      {kBase + "soil: {preset: loam, stiffness: [1, 1]}\n", "soil.preset", "not both"},
      {kBase + "soil: {stiffness: [1e5, 1e5], damping: [1, 1]}\n", "soil.mass", "missing"},
      {kBase + "soil: {stiffness: [1e5], damping: [1, 1], mass: [1, 1]}\n", "soil.stiffness", "list of 2"},
      {kBase + "terrain: {profile: [[0, 0], [0, 1]]}\n", "terrain.profile[1][0]", "increase"},
      {kBase + "terrain: {height: 0, profile: [[0, 0], [1, 1]]}\n", "terrain.profile", "not both"},
      {kBase + "sensors: {latency_cycles: 100}\n", "sensors.latency_cycles", "[0, 63]"},
      {kBase + "sensors: {latency_cycles: 1.5}\n", "sensors.latency_cycles", "whole number"},
      {kBase + "sensors: {position_noise: [0, 0, x, 0]}\n", "sensors.position_noise[2]", "number"},
      {kBase + "checks: {constraint_tolerance: 0}\n", "checks.constraint_tolerance", "allowed range"},
      {"name: t\nduration: 1\ninitial_state: {q_a: [0, 3.5, 2.3, 2.1]}\n", "initial_state.q_a[1]", "[1.7, 2.83]"},
      {"name: t\nduration: 1\n", "initial_state.q_a", "missing"},
      {"duration: 1\ninitial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n", "name", "missing"},
      {"name: t\ninitial_state: {q_a: [0, 2.4626, 2.3231, 2.1447]}\n", "duration", "missing"},
      {kBase + "machine: no/such/machine.yaml\n", "machine", "does not load"},
      {kBase + "integrator: [1, 2]\n", "integrator", "mapping"},
      {"name: [unclosed\n", "(file)", "not valid YAML"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.yaml);
    const std::string e = error_of(c.yaml);
    CAPTURE(e);
    REQUIRE_FALSE(e.empty());
    CHECK(contains(e, "bad.yaml: " + c.field + ": "));
    CHECK(contains(e, c.allowed));
  }
}

TEST_CASE("plant/scene keeps the firmware's controller and task sections unchecked") {
  const Scene s = load_scene_from_string(kBase + "controller: {anything: [1, 2]}\ntask: {type: whatever, x: 1}\n", "ok.yaml");
  CHECK(s.has_controller);
  CHECK(s.has_task);
  CHECK(contains(s.text, "anything"));
}

TEST_CASE("plant/scene shipped scenes load and their initial states assemble") {
  for (const char* name : {"free_motion.yaml", "dig.yaml"}) {
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
  CHECK(load_scene_from_string("name: t\nduration: 28800\n" + task, "ok.yaml").duration == 28800);
  const std::string e = error_of("name: t\nduration: 28801\n" + task);
  CAPTURE(e);
  CHECK(contains(e, "bad.yaml: duration: is 28801; allowed range [0.001, 28800]"));
}
