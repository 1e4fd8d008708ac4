// The plant's sections of a scene file, each field declared once with the settings reader.
#include "sim_plant/scene.hpp"

#include <cmath>

#include "model/scene_common_reader.hpp"
#include "settings/section_reader.hpp"
#include "sim_plant/integration_methods.hpp"

namespace exc::plant {

namespace {

using settings::format_number;
using settings::Need;
using settings::SectionReader;

// Soil: a preset or explicit K, B, M (machine.md).
void read_soil(SectionReader& soil, Scene& s) {
  const bool explicit_soil = soil.has("stiffness") || soil.has("damping") || soil.has("mass");
  if (explicit_soil && soil.has("preset")) soil.fail("preset", "give either 'preset' or stiffness/damping/mass, not both");
  if (explicit_soil) {
    soil.others({"preset"});
    soil.numbers("stiffness", s.soil.stiffness, {0, 1e9}, "N/m", "K_t on x and z", Need::required);
    soil.numbers("damping", s.soil.damping, {0, 1e7}, "N s/m", "B_t on x and z", Need::required);
    soil.numbers("mass", s.soil.mass, {0, 1e4}, "kg", "M_t on x and z", Need::required);
  } else {
    soil.choice("preset", s.soil_preset, kSoilPresets, "machine.md's K_t, B_t, M_t");
    soil.others({"stiffness", "damping", "mass"});
    s.soil = soil_preset(s.soil_preset);
  }
  soil.finish();
}

void read_integrator(SectionReader& integ, Scene& s) {
  IntegratorSettings& i = s.integrator;
  integ.choice("method", i.method, integration_methods(), "the integration method");
  integ.choice("formulation", i.formulation, kFormulations, "the equations integrated");
  integ.number("cycle", s.cycle, {1e-4, 1.0}, "s", "one plant step (the SYNC period)");
  i.step = s.cycle;
  integ.number("step", i.step, {1e-6, 1.0}, "s", "integration substep (default: the cycle)");
  const double ratio = s.cycle / i.step;
  if (i.step > s.cycle * (1 + 1e-9) || std::abs(ratio - std::round(ratio)) > 1e-6 * ratio)
    integ.fail("step", "is " + format_number(i.step) + " s; must divide integrator.cycle (" + format_number(s.cycle) +
                           " s) a whole number of times, e.g. " + format_number(s.cycle) + ", " +
                           format_number(s.cycle / 2) + ", " + format_number(s.cycle / 4));
  integ.number("baumgarte_alpha", i.baumgarte_alpha, {0, 1e4}, "1/s", "augmented_baumgarte velocity gain");
  integ.number("baumgarte_beta", i.baumgarte_beta, {0, 1e4}, "1/s", "augmented_baumgarte position gain");
  integ.whole("implicit_max_iterations", i.implicit_max_iterations, 1, 100, "", "implicit midpoint iterations");
  integ.number("implicit_tolerance", i.implicit_tolerance, {1e-14, 1e-3}, "", "on the midpoint velocity residual");
  integ.choice("pressure_method", i.pressure_method, kPressureMethods, "hydraulic: the chamber pressures' integration");
  integ.finish();
}

void read_sensors(SectionReader& sens, SensorParameters& sp) {
  sens.numbers("position_quantum", sp.position_quantum, {0, 0.1}, "", "rad (swing), m: resolution");
  sens.numbers("position_noise", sp.position_noise, {0, 0.1}, "", "rad (swing), m: standard deviation");
  sens.numbers("velocity_noise", sp.velocity_noise, {0, 1.0}, "", "rad/s (swing), m/s: standard deviation");
  sens.number("pressure_quantum", sp.pressure_quantum, {0, 1e7}, "Pa", "pressure resolution");
  sens.number("pressure_noise", sp.pressure_noise, {0, 5e6}, "Pa",
              "standard deviation on every chamber and pump pressure reading (transmitter noise, pump ripple)");
  sens.number("spool_noise", sp.spool_noise, {0, 0.1}, "",
              "standard deviation of each spool position reading, a fraction of the stroke (hydraulic plant)");
  sens.whole("seed", sp.seed, 0, 4294967295.0, "", "noise seed (runs are reproducible)");
  sens.whole("latency_cycles", sp.latency_cycles, 0, SensorParameters::kMaxLatency, "", "readings lag by this many cycles");
  sens.finish();
}

void read_checks(SectionReader& chk, CheckSettings& c) {
  chk.number("constraint_tolerance", c.constraint_tolerance, {1e-12, 1}, "m", "loop-closure residual limit");
  chk.number("energy_tolerance", c.energy_tolerance, {0, 1e9}, "J", "slack of the energy balance");
  chk.number("energy_relative_tolerance", c.energy_relative_tolerance, {0, 10}, "", "plus this fraction of the work exchanged");
  chk.number("end_stop_margin", c.end_stop_margin, {0, 1}, "m", "past a stroke limit counts as through it (ideal actuators)");
  chk.number("pressure_check_margin", c.pressure_check_margin, {0, 50e6}, "Pa",
             "hydraulic: a chamber above the highest relief by more stops the plant");
  chk.finish();
}

}  // namespace

Scene read_scene(const settings::Document& doc, const SceneMachine& machine) {
  SectionReader top(doc);
  Scene s;
  s.file = doc.file();
  SceneCommon common = read_scene_common(top, machine);
  s.name = common.name;
  s.description = common.description;
  s.machine_file = common.machine_file;
  s.machine = std::move(common.machine);
  s.duration = common.duration;
  s.terrain = common.terrain;
  const Machine& m = s.machine;

  SectionReader soil = top.section("soil", "the soil model");
  read_soil(soil, s);

  // Initial state inside the machine's limits.
  SectionReader init = top.section("initial_state", "where the machine starts");
  Vec4 qlo = m.q_min(), qhi = m.q_max();
  qlo[0] = -2 * M_PI;
  qhi[0] = 2 * M_PI;
  init.numbers("q_a", s.q_a0, qlo, qhi, "", "[swing rad, L_boom, L_arm, L_bucket m]", Need::required);
  init.numbers("qd_a", s.qd_a0, Vec4(-m.speed_max()), m.speed_max(), "", "rad/s, m/s inside the speed limits");
  init.finish();

  SectionReader act = top.section("actuators", "how the actuators are modelled (their numbers: the machine file)");
  act.choice("fidelity", s.actuators.fidelity, actuator_fidelities(), "the actuator model");
  act.number("lag", s.actuators.lag, {0, 1}, "s", "limited: effort time constant");
  act.finish();

  SectionReader integ = top.section("integrator", "the integration of the dynamics");
  read_integrator(integ, s);
  SectionReader sens = top.section("sensors", "what the sensors add");
  read_sensors(sens, s.sensors);
  SectionReader chk = top.section("checks", "the plant's watchdogs");
  read_checks(chk, s.checks);

  top.others(kFirmwareSceneSections);
  s.has_controller = top.has("controller");
  s.has_task = top.has("task");
  top.finish();
  s.effective = top.effective();
  return s;
}

Scene read_scene(const settings::Document& doc) {
  SectionReader top(doc);
  return read_scene(doc, read_scene_machine(top, doc));
}

Scene load_scene(const std::string& path) { return read_scene(settings::Document::load(path)); }

}  // namespace exc::plant
