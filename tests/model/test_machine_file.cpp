// The machine file: the shipped reference machine, the embedded copy, and errors that name the file,
// the field and the reason.
#include <doctest/doctest.h>

#include <fstream>
#include <regex>

#include "model/machine.hpp"
#include "text_file.hpp"

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
void check_error(const std::string& yaml, const std::string& field, const std::string& reason_part) {
  try {
    load_machine_from_string(yaml, "bad.yaml");
    FAIL("no MachineError for field " << field);
  } catch (const MachineError& e) {
    CHECK(e.file() == "bad.yaml");
    CHECK(e.field() == field);
    CHECK(e.reason().find(reason_part) != std::string::npos);
    const std::string what = e.what();
    CHECK(what.find("bad.yaml") != std::string::npos);
    CHECK(what.find(field) != std::string::npos);
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

TEST_CASE("model/machine file errors name the file, the field and the reason") {
  check_error(edited("mass: 1700,", "mass: -5,"), "bodies.boom.mass", "outside the allowed range");
  check_error(edited("mass: 1700,", "mass: heavy,"), "bodies.boom.mass", "not a number");
  check_error(edited("  boom:          { mass: 1700,  com: [2.54, 0, 0.68],   inertia: [200, 4050, 3900] }\n", ""),
              "bodies.boom", "missing");
  check_error(edited("com: [2.54, 0, 0.68]", "com: [2.54, 0.68]"), "bodies.boom.com", "list of 3 numbers");
  check_error(edited("inertia: [200, 4050, 3900]", "inertia: [200, 4050, 9900]"), "bodies.boom.inertia",
              "not a physical body");
  check_error(edited("length: [1.70, 2.83]", "length: [2.83, 1.70]"), "actuators.boom.length", "below max");
  check_error(edited("force: [-184000, 356000]", "force: [184000, 356000]"), "actuators.bucket.force", "pull");
  check_error(edited("gravity: 9.81", "gravity: .inf"), "gravity", "finite");
  check_error(edited("gravity: 9.81", "gravity: 0"), "gravity", "outside the allowed range [0.1, 100]");
  check_error(edited("H: [5.6479, 0.0]", "H: [5.6479, 0.2]"), "pins.boom.H", "boom x axis");
  check_error(edited("JK: 0.6669", "JQ: 0.6669"), "pins.link_lengths.JQ", "unknown field");
  check_error(edited("name: reference-20t", "name: reference-20t\nswing_hieght: 3"), "swing_hieght", "unknown field");
  check_error(edited("q_a: [0.5, 1.9, 3.0, 1.8]", "q_a: [0.5, 1.9, 3.0]"), "reference_poses[1].q_a",
              "list of 4 numbers");
  check_error("name: [unclosed", "line 1", "YAML syntax");
  check_error("", "", "not a YAML mapping");
  try {
    load_machine("/nonexistent/machine.yaml");
    FAIL("no error for a missing file");
  } catch (const MachineError& e) {
    CHECK(e.file() == "/nonexistent/machine.yaml");
    CHECK(e.reason().find("cannot open") != std::string::npos);
  }
}
