#pragma once
// Scenes for the plant's tests, written as YAML text so that they go through the real loader.
#include <string>

#include <vector>

#include "sim_plant/integration_methods.hpp"
#include "sim_plant/plant.hpp"

namespace exc::plant::test {

// The first reference pose of reference-machine.yaml: tip at about (8.66, 1.83) m.
inline const char* kReferencePose = "[0.0, 2.4626, 2.3231, 2.1447]";

struct SceneText {
  std::string method = "semi_implicit_euler";
  std::string formulation = "independent";
  double step = 1e-3;
  double cycle = 1e-3;
  std::string q_a = kReferencePose;
  std::string qd_a = "[0, 0, 0, 0]";
  std::string terrain = "height: 0.0";
  std::string soil = "preset: none";
  std::string actuators = "fidelity: ideal";
  std::string extra_integrator;  // more "key: value" lines for the integrator section
  std::string checks = "energy_tolerance: 100";
  std::string sensors = "seed: 1";

  std::string yaml() const {
    auto num = [](double v) {
      char b[64];
      std::snprintf(b, sizeof b, "%.17g", v);
      return std::string(b);
    };
    return "name: test\n"
           "terrain: {" + terrain + "}\n"
           "soil: {" + soil + "}\n"
           "initial_state: {q_a: " + q_a + ", qd_a: " + qd_a + "}\n"
           "actuators: {" + actuators + "}\n"
           "integrator: {method: " + method + ", formulation: " + formulation + ", step: " + num(step) +
           ", cycle: " + num(cycle) + (extra_integrator.empty() ? "" : ", " + extra_integrator) + "}\n"
           "duration: 10\n"
           "sensors: {" + sensors + "}\n"
           "checks: {" + checks + "}\n";
  }
  Scene scene() const { return read_scene(settings::Document::parse(yaml(), "<test>")); }
  // The defaults with an integrator and its step (= the cycle).
  static SceneText stepped(const std::string& method, const std::string& formulation, double h) {
    SceneText t;
    t.method = method;
    t.formulation = formulation;
    t.step = h;
    t.cycle = h;
    return t;
  }
};

// Free motion: gravity off, zero efforts, an initial velocity on every axis (a conservative system),
// the energy and constraint checks left to the test.
inline Scene free_motion_scene(const std::string& method, const std::string& formulation, double h) {
  SceneText t = SceneText::stepped(method, formulation, h);
  t.qd_a = "[0.3, 0.04, -0.06, 0.08]";
  t.checks = "energy_tolerance: 1e9, constraint_tolerance: 1";
  Scene s = t.scene();
  s.machine.gravity = 0;
  return s;
}

// The reference machine with its hydraulics at the reference pose, the tip 1.8 m above flat ground (no soil).
inline Scene hydraulic_scene() {
  SceneText t;
  t.actuators = "fidelity: hydraulic";
  return t.scene();
}

// Every spool at an opening (-1..1), the plant's own valve command.
inline ActuatorCommand valve(const Vec4& opening) {
  ActuatorCommand c;
  c.mode = ActuatorCommand::valve;
  c.value = opening;
  return c;
}

// The shipped scenes that drive the hydraulic machine through its valves, and whether their swing
// moves (flow-based control lags a moving swing past its tracking limit: not run there).
struct ShippedHydraulicScene {
  const char* scene;
  bool swing_moves;
};
inline constexpr ShippedHydraulicScene kShippedHydraulicScenes[] = {
    {"dig.yaml", false},       {"free_motion.yaml", true},      {"clay_slope.yaml", false},     {"sand_skim.yaml", false},
    {"loam_noisy_late.yaml", false}, {"truck_loading.yaml", true}, {"truck_clay_slope.yaml", true}};

// Every registered integration method (in the suites that register none: the shipped ones), so a
// method added by its registration line is held to the same energy, accuracy and stability tests.
inline std::vector<std::string> methods() { return integration_methods().name_list(); }
inline const char* kFormulations[] = {"independent", "augmented_baumgarte", "augmented_projection"};

}  // namespace exc::plant::test
