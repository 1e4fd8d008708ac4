// The machine file: the shipped reference machine, the embedded copy, and errors that name the file,
// the field and the reason.
#include <doctest/doctest.h>

#include <fstream>

#include "model/machine.hpp"
#include "settings_error_check.hpp"
#include "text_file.hpp"
#include "model/machine_reader.hpp"

using namespace exc;

using exc::test::read_text_file;

namespace {
// The reference text with one substring replaced (the edit must apply exactly once).
std::string edited(const std::string& from, const std::string& to) {
  std::string text = read_text_file(EXC_MACHINE_FILE);
  const auto pos = text.find(from);
  REQUIRE(pos != std::string::npos);
  REQUIRE(text.find(from, pos + 1) == std::string::npos);
  return text.replace(pos, from.size(), to);
}
// The error must name bad.yaml, the field, the place where `at` begins, and the reason part.
void check_error(const std::string& yaml, const std::string& field, const std::string& at, const std::string& reason_part) {
  try {
    load_machine_from_string(yaml, "bad.yaml");
    FAIL("no SettingsError for field " << field);
  } catch (const SettingsError& e) {
    exc::test::check_settings_error(e, "bad.yaml", yaml, field, at, reason_part);
  }
}
}  // namespace

TEST_CASE("model/the shipped machine file carries the numbers of the spec") {
  const Machine m = load_machine(EXC_MACHINE_FILE);
  CHECK(m.source == EXC_MACHINE_FILE);
  CHECK(m.name == "reference-20t");
  CHECK(m.gravity == 9.81);
  CHECK(m.swing_height == 1.1266);
  CHECK(m.C == Vec2(0.4789, 0.5714));
  CHECK(m.D == Vec2(1.1751, 0.2233));
  CHECK(m.E == Vec2(2.2503, 1.0077));
  CHECK(m.F == Vec2(3.1802, 1.3866));
  CHECK(m.H == Vec2(5.6479, 0.0));
  CHECK(m.G == Vec2(-0.8094, 0.2159));
  CHECK(m.I == Vec2(0.3525, 0.5552));
  CHECK(m.K == Vec2(2.2357, 0.0955));
  CHECK(m.M == Vec2(2.9319, 0.0));
  CHECK(m.L == Vec2(0.5567, 0.0));
  CHECK(m.T == Vec2(-0.2056, -1.4248));
  CHECK(m.JL == 0.6595);
  CHECK(m.JK == 0.6669);
  CHECK(m.bodies[kSwing].mass == 11500);
  CHECK(m.bodies[kBucket].com == Vec3(0.34, 0, -0.69));
  CHECK(m.bodies[kLink12].inertia == Vec3(0.4, 2.6, 2.6));
  CHECK(m.bodies[kArmRod].mass == 110);
  CHECK(m.q_min().tail<3>() == Vec3(1.70, 2.11, 1.62));
  CHECK(m.q_max().tail<3>() == Vec3(2.83, 3.47, 2.38));
  CHECK(std::isinf(m.q_min()[0]));
  CHECK(m.effort_min() == Vec4(-65000, -387000, -248000, -184000));
  CHECK(m.effort_max() == Vec4(65000, 776000, 491000, 356000));
  CHECK(m.speed_max() == Vec4(1.3, 0.32, 0.50, 0.70));
  CHECK(m.relief_pressure == 34.3e6);
  REQUIRE(m.reference_poses.size() == 2);
  CHECK(m.reference_poses[1].q_a == Vec4(0.5, 1.9, 3.0, 1.8));
  CHECK(m.reference_poses[1].pins_world.size() == 8);
  CHECK(m.terrain_flat_height == 0.0);

  // The spec's own file gives the same machine (the project's copy only changes comments).
  // (Only where the spec tree sits beside the project, as in the development workspace.)
  const std::string spec_path = EXC_SOURCE_DIR "/../shared/spec/reference-machine.yaml";
  if (std::ifstream(spec_path)) {
    const Machine spec = load_machine(spec_path);
    CHECK(spec.E == m.E);
    CHECK(spec.reference_poses[0].pins_world == m.reference_poses[0].pins_world);
    for (int i = 0; i < kNumJoints; ++i) CHECK(spec.bodies[i].inertia == m.bodies[i].inertia);
  }
}

TEST_CASE("model/the embedded reference machine equals the machine file") {
  const Machine a = reference_machine();
  const Machine b = load_machine(EXC_MACHINE_FILE);
  CHECK(a.source == "<embedded>");
  CHECK(a.name == b.name);
  CHECK(a.T == b.T);
  CHECK(a.bucket.max_force == b.bucket.max_force);
  for (int i = 0; i < kNumJoints; ++i) {
    CHECK(a.bodies[i].mass == b.bodies[i].mass);
    CHECK(a.bodies[i].com == b.bodies[i].com);
  }
}

TEST_CASE("model/machine file errors name the file, the line and column, the field and the reason") {
  check_error(edited("mass: 1700,", "mass: -5,"), "bodies.boom.mass", "-5,", "is -5 kg; allowed range [0.001, 1000000] kg");
  check_error(edited("mass: 1700,", "mass: heavy,"), "bodies.boom.mass", "heavy", "'heavy' is not a number; allowed range");
  // A missing body: named at its section (the mapping of bodies begins at its first key).
  check_error(edited("  boom:          { mass: 1700,  com: [2.54, 0, 0.68],   inertia: [200, 4050, 3900] }\n", ""),
              "bodies.boom", "swing:         { mass: 11500", "missing");
  check_error(edited("com: [2.54, 0, 0.68]", "com: [2.54, 0.68]"), "bodies.boom.com", "[2.54, 0.68]",
              "must be a list of 3 numbers in [-50, 50] m");
  check_error(edited("inertia: [200, 4050, 3900]", "inertia: [200, 4050, 9900]"), "bodies.boom.inertia",
              "[200, 4050, 9900]", "not a physical body");
  check_error(edited("length: [1.70, 2.83]", "length: [2.83, 1.70]"), "actuators.boom.length", "[2.83, 1.70]",
              "min 2.83 must be below max 1.7");
  check_error(edited("force: [-184000, 356000]", "force: [184000, 356000]"), "actuators.bucket.force",
              "[184000, 356000]", "pull < 0");
  check_error(edited("gravity: 9.81", "gravity: .inf"), "gravity", ".inf", "is inf m/s^2; allowed range [0.1, 100] m/s^2");
  check_error(edited("gravity: 9.81", "gravity: 0"), "gravity", "0\n\nswing:", "is 0 m/s^2; allowed range [0.1, 100] m/s^2");
  check_error(edited("H: [5.6479, 0.0]", "H: [5.6479, 0.2]"), "pins.boom.H", "[5.6479, 0.2]", "boom x axis");
  check_error(edited("JK: 0.6669", "JK: 0.6669, JQ: 1"), "pins.link_lengths.JQ", "JQ", "unknown key; allowed keys: JL, JK");
  // A misspelt required key is first a missing one, named at its section (a flow mapping: its brace).
  check_error(edited("JK: 0.6669", "JQ: 0.6669"), "pins.link_lengths.JK", "{ JL:", "missing: link 12");
  check_error(edited("name: reference-20t", "name: reference-20t\nswing_hieght: 3"), "swing_hieght", "swing_hieght",
              "unknown key; allowed keys: name, gravity, swing, frames, assembly, pins, bodies, actuators, hydraulics, "
              "reference_poses, terrain");
  check_error(edited("q_a: [0.5, 1.9, 3.0, 1.8]", "q_a: [0.5, 1.9, 3.0]"), "reference_poses[1].q_a", "[0.5, 1.9, 3.0]",
              "list of 4 numbers");
  // The measured poses against the geometry: a link edited without its poses, a pose's pin or angle
  // edited without the geometry, a pose the geometry cannot assemble.
  check_error(edited("JL: 0.6595", "JL: 0.6695"), "reference_poses[0].bucket_angle_deg", "69.875",
              "the geometry gives 68.844 deg at this q_a, the pose 69.875 (tolerance 0.01 deg)");
  check_error(edited("G: [5.7662, 3.1501, 0.9126]", "G: [5.7672, 3.1501, 0.9126]"), "reference_poses[1].pins_world.G",
              "[5.7672, 3.1501, 0.9126]", "the geometry puts pin G at (5.7662, 3.1501, 0.9126), the pose at (5.7672, 3.1501, 0.9126), 1.0 mm away");
  check_error(edited("arm_angle_deg: -60.012", "arm_angle_deg: -60.5"), "reference_poses[0].arm_angle_deg", "-60.5",
              "the geometry gives -60.012 deg");
  check_error(edited("q_a: [0.5, 1.9, 3.0, 1.8]", "q_a: [0.5, 9.9, 3.0, 1.8]"), "reference_poses[1].q_a", "[0.5, 9.9, 3.0, 1.8]",
              "the geometry does not assemble at it: no assembly");
  {
    // The controls: a pin moved by 0.4 mm is within the file's tolerance; the edited link loads once
    // its poses are removed (a machine without measured poses is still a machine).
    CHECK_NOTHROW(load_machine_from_string(edited("G: [5.7662, 3.1501, 0.9126]", "G: [5.7666, 3.1501, 0.9126]"), "ok.yaml"));
    std::string no_poses = edited("JL: 0.6595", "JL: 0.6695");
    const auto poses = no_poses.find("reference_poses:");
    const auto terrain = no_poses.find("\nterrain:");
    REQUIRE(poses != std::string::npos);
    REQUIRE(terrain != std::string::npos);
    no_poses.erase(poses, terrain + 1 - poses);
    CHECK(load_machine_from_string(no_poses, "no_poses.yaml").reference_poses.empty());
  }
  check_error(edited("bulk_modulus: 1.0e9", "bulk_modulus: 1.0e6"), "hydraulics.bulk_modulus", "1.0e6",
              "is 1000000 Pa; allowed range [1e+07, 5e+09] Pa");
  check_error(edited("pump_of: [1, 0, 1, 0]", "pump_of: [1, 0, 0.5, 0]"), "hydraulics.pump_of[2]", "0.5, 0]",
              "is 0.5; allowed values: 0, 1");
  {
    std::string t = edited("vapour_pressure: 0.0 ", "vapour_pressure: 0.09e6 ");
    t.replace(t.find("tank_pressure: 0.3e6"), 20, "tank_pressure: 0.05e6");
    check_error(t, "hydraulics.vapour_pressure", "0.09e6", "is 90000 Pa; must not exceed tank_pressure (50000 Pa)");
  }
  check_error(edited("tank_pressure: 0.3e6", "tank_pressure: 0.3e6\n  colour: 1"), "hydraulics.colour", "colour",
              "unknown key; allowed keys: valve_time_constant, bulk_modulus");
  try {
    load_machine_from_string("name: x\ngravity: [unclosed\n", "bad.yaml");
    FAIL("no error for bad YAML");
  } catch (const SettingsError& e) {
    CHECK(e.file() == "bad.yaml");
    CHECK(e.line() == 3);  // the end of the file, where the list should have closed
    CHECK(e.reason().rfind("not valid YAML: ", 0) == 0);
  }
  try {
    load_machine_from_string("", "empty.yaml");
    FAIL("no error for an empty file");
  } catch (const SettingsError& e) {
    CHECK(e.file() == "empty.yaml");
    CHECK(e.reason().find("a YAML mapping is required") != std::string::npos);
  }
  try {
    load_machine("/nonexistent/machine.yaml");
    FAIL("no error for a missing file");
  } catch (const SettingsError& e) {
    CHECK(e.file() == "/nonexistent/machine.yaml");
    CHECK(e.line() == 0);
    CHECK(std::string(e.what()) == "/nonexistent/machine.yaml: cannot open the file");
  }
}

TEST_CASE("model/the machine file carries the hydraulics, equal to the documented defaults, and C++ edits are checked by the same declarations") {
  const Machine m = load_machine(EXC_MACHINE_FILE);
  const HydraulicParameters d;
  const HydraulicParameters& h = m.hydraulics;
  CHECK(h.valve_time_constant == d.valve_time_constant);
  CHECK(h.bulk_modulus == d.bulk_modulus);
  CHECK(h.dead_volume == d.dead_volume);
  CHECK(h.swing_volume == d.swing_volume);
  CHECK(h.supply_pressure == d.supply_pressure);
  CHECK(h.tank_pressure == d.tank_pressure);
  CHECK(h.valve_pressure_drop == d.valve_pressure_drop);
  CHECK(h.laminar_pressure == d.laminar_pressure);
  CHECK(h.pump_flow == 439.0 / 60000.0);
  CHECK(h.pumps_merged == d.pumps_merged);
  CHECK(h.pump_of == d.pump_of);
  CHECK(h.load_sensing_margin == d.load_sensing_margin);
  CHECK(h.main_relief_pressure == d.main_relief_pressure);
  CHECK(h.port_relief_pressure == d.port_relief_pressure);
  CHECK(h.swing_relief_pressure == d.swing_relief_pressure);
  CHECK(h.relief_override == d.relief_override);
  CHECK(h.makeup_pressure_drop == d.makeup_pressure_drop);
  CHECK(h.vapour_pressure == d.vapour_pressure);
  CHECK(h.pilot_full_stroke == d.pilot_full_stroke);
  CHECK(h.dead_zone_extend == d.dead_zone_extend);
  CHECK(h.dead_zone_retract == d.dead_zone_retract);
  CHECK(reference_machine().hydraulics.pump_flow == h.pump_flow);
  CHECK_NOTHROW(validate_hydraulics(m));
  Machine bad = m;
  bad.hydraulics.dead_zone_extend[2] = 0.95;
  try {
    validate_hydraulics(bad);
    FAIL("no error");
  } catch (const SettingsError& e) {
    CHECK(e.file() == EXC_MACHINE_FILE);
    CHECK(e.line() == 0);  // not from the file
    CHECK(e.field() == "hydraulics.dead_zone_extend[2]");
    CHECK(e.reason() == "is 0.95 (not from the file); allowed range [0, 0.9]");
  }
}
