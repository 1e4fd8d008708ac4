// A sweep's knobs name settings: their type and range are the setting's one declaration (recorded by
// the settings reader), a case's values are read by the scene's own readers, a value they refuse is
// refused when the spec loads, and each file is loaded once per process.
#include <doctest/doctest.h>

#include <sstream>

#include <map>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "harness/scene_source.hpp"
#include "sim_plant/integration_methods.hpp"
#include "settings_error_check.hpp"
#include "sim_runs.hpp"
#include "sweep_knobs.hpp"

namespace fs = std::filesystem;
using exc::settings::Declaration;
using exc::sim::SceneBundle;
using exc::sim::SceneChanges;
using exc::sim::SweepRun;
using exc::sim::SweepValue;
using exc::test::kDig;
using exc::test::read_text_file;
using exc::test::run_sim;

namespace {

const exc::sim::SceneSource& dig() {
  static const exc::sim::SceneSource source = exc::sim::load_scene_source(kDig);
  return source;
}

SweepValue number(double x) { return SweepValue{SweepValue::Type::number, x, {}, ""}; }

// The case's scene with one knob set.
SceneBundle with(const std::string& knob, const SweepValue& value, SweepRun run = SweepRun::closed_loop) {
  SceneChanges changes(dig());
  exc::sim::set_knob(run, knob, value, changes);
  return changes.read();
}

// The settings error a read of the scene with `path` set to `value` raises.
exc::settings::SettingsError refusal(const std::string& path, const YAML::Node& value) {
  SceneChanges changes(dig());
  changes.set(path, value);
  try {
    (void)changes.read();
  } catch (const exc::settings::SettingsError& e) {
    return e;
  }
  FAIL("the readers took " << path);
  throw;
}

}  // namespace

TEST_CASE("tools/settings: the reader records each field's declaration in the document read: type, count, range, unit") {
  const Declaration* latency = dig().declaration("sensors.latency_cycles");
  REQUIRE(latency != nullptr);
  CHECK(latency->type == Declaration::Type::whole);
  CHECK(latency->bounds_of(0).lo == 0);
  CHECK(latency->bounds_of(0).hi == exc::plant::SensorParameters::kMaxLatency);  // the sensors' ring holds this many
  const Declaration* noise = dig().declaration("sensors.position_noise");
  REQUIRE(noise != nullptr);
  CHECK(noise->type == Declaration::Type::numbers);
  CHECK(noise->count == 4);
  CHECK(noise->bounds_of(3).hi == 0.1);
  const Declaration* t_f = dig().declaration("controller.valves.force_time_constant");  // the firmware's side
  REQUIRE(t_f != nullptr);
  CHECK(t_f->unit == "s");
  CHECK(t_f->bounds_of(0).lo == 1e-3);
  const Declaration* oil = dig().declaration("machine.hydraulics.bulk_modulus");  // the machine file's (machine.hpp: [1e7, 5e9])
  REQUIRE(oil != nullptr);
  CHECK(oil->unit == "Pa");
  CHECK(oil->bounds_of(0).lo == 1e7);
  CHECK(oil->bounds_of(0).hi == 5e9);
  const Declaration* method = dig().declaration("integrator.method");
  REQUIRE(method != nullptr);
  CHECK(method->type == Declaration::Type::choice);
  CHECK(method->what == exc::plant::integration_methods().names());
  CHECK(dig().declaration("sensors.no_such_field") == nullptr);
  CHECK(dig().declaration("soil.stiffness") == nullptr);  // the dig's soil is a preset: its K is not read
}

TEST_CASE("tools/sweep knobs: a value set by a setting's path reaches the side that reads it, and one the readers refuse names the setting and its range") {
  const SceneBundle& nominal = dig().nominal;
  SceneChanges sensors(dig());
  sensors.set("sensors.latency_cycles", YAML::Node("5"));
  CHECK(sensors.read().scene.sensors.latency_cycles == 5);
  // The plant's machine and the firmware's model of it apart.
  SceneChanges plant_oil(dig());
  plant_oil.set("machine.hydraulics.bulk_modulus", YAML::Node("3e8"));
  const SceneBundle a = plant_oil.read();
  CHECK(a.scene.machine.hydraulics.bulk_modulus == 3e8);
  CHECK(a.firmware.machine.hydraulics.bulk_modulus == nominal.firmware.machine.hydraulics.bulk_modulus);
  SceneChanges model_oil(dig());
  model_oil.set("firmware.machine.hydraulics.bulk_modulus", YAML::Node("3e8"));
  const SceneBundle b = model_oil.read();
  CHECK(b.firmware.machine.hydraulics.bulk_modulus == 3e8);
  CHECK(b.scene.machine.hydraulics.bulk_modulus == nominal.scene.machine.hydraulics.bulk_modulus);
  // What the controller derives from the machine at load follows the firmware's model: its spools
  // 0.1 s (the file's 0.03 s) give the force loop's time constant 0.1 s and the lead's target a third.
  SceneChanges model_spools(dig());
  model_spools.set("firmware.machine.hydraulics.valve_time_constant", YAML::Node("0.1"));
  const SceneBundle spools = model_spools.read();
  REQUIRE(nominal.firmware.machine.hydraulics.valve_time_constant == doctest::Approx(0.03));
  CHECK(spools.firmware.machine.hydraulics.valve_time_constant == 0.1);
  CHECK(spools.firmware.controller.actuation.valves.force_time_constant == doctest::Approx(0.1));
  CHECK(spools.firmware.controller.actuation.valves.spool_lag_target == doctest::Approx(0.1 / 3));
  CHECK(nominal.firmware.controller.actuation.valves.force_time_constant == doctest::Approx(0.03));
  SceneChanges controller(dig());
  controller.set("controller.valves.force_time_constant", YAML::Node("0.01"));
  CHECK(controller.read().firmware.controller.actuation.valves.force_time_constant == 0.01);

  // Refused as the scene file would be: the sensors' ring, a machine range, a cross-field rule.
  const exc::settings::SettingsError late = refusal("sensors.latency_cycles", YAML::Node("64"));
  CHECK(late.field() == "sensors.latency_cycles");
  CHECK(late.reason().find("[0, 63]") != std::string::npos);
  const exc::settings::SettingsError oil = refusal("machine.hydraulics.bulk_modulus", YAML::Node("1e3"));
  CHECK(oil.field() == "hydraulics.bulk_modulus");
  CHECK(oil.reason().find("[1e+07, 5e+09] Pa") != std::string::npos);
  YAML::Node ki(YAML::NodeType::Sequence);
  for (int i = 0; i < 4; ++i) ki.push_back("2000");  // above kv kp = 1024: e''' + kv e'' + kp e' + ki e unstable
  const exc::settings::SettingsError unstable = refusal("controller.ki", ki);
  CHECK(unstable.field() == "controller.ki[0]");
  CHECK(unstable.reason().find("unstable") != std::string::npos);
}

TEST_CASE("tools/sweep knobs: the named knobs write the settings their rows name, from the nominal scene's values") {
  const SceneBundle& nominal = dig().nominal;
  const SceneBundle gains = with("gain_scale", number(2));
  CHECK(gains.firmware.controller.pid.gains.kp == nominal.firmware.controller.pid.gains.kp * 4);
  CHECK(gains.firmware.controller.pid.gains.kv == nominal.firmware.controller.pid.gains.kv * 2);
  CHECK(gains.firmware.controller.pid.gains.ki == nominal.firmware.controller.pid.gains.ki * 8);
  CHECK(gains.firmware.controller.slotine_li.lambda == nominal.firmware.controller.slotine_li.lambda * 2);
  const SceneBundle rates = with("adaptation_scale", number(0.01));
  CHECK(rates.firmware.controller.adaptation.rate == nominal.firmware.controller.adaptation.rate * 0.01);
  CHECK(rates.firmware.controller.slotine_li.adaptation_rate == nominal.firmware.controller.slotine_li.adaptation_rate * 0.01);
  const SceneBundle heavy = with("model_mass", number(0.2));
  for (std::size_t i = 0; i < heavy.firmware.machine.bodies.size(); ++i) {
    CHECK(heavy.firmware.machine.bodies[i].mass == nominal.firmware.machine.bodies[i].mass * 1.2);
    CHECK(heavy.firmware.machine.bodies[i].inertia == nominal.firmware.machine.bodies[i].inertia * 1.2);
    CHECK(heavy.scene.machine.bodies[i].mass == nominal.scene.machine.bodies[i].mass);  // the plant keeps the true machine
  }
  const SceneBundle stiff = with("soil_stiffness", number(3));
  CHECK(stiff.scene.soil.stiffness == nominal.scene.soil.stiffness * 3);
  CHECK(stiff.scene.soil.damping == nominal.scene.soil.damping);
  CHECK(with("delay_cycles", number(2)).scene.sensors.latency_cycles == 2);
  CHECK(with("position_noise", number(1e-4)).scene.sensors.position_noise == exc::Vec4::Constant(1e-4));
  // The open loop's: the integrator by its two names, the step with its cycle, the soil's damping ratio kept.
  const SceneBundle rk4 = with("integrator", SweepValue{SweepValue::Type::name, 0, {}, "rk4/augmented_baumgarte"},
                               SweepRun::open_loop);
  CHECK(rk4.scene.integrator.method == "rk4");
  CHECK(rk4.scene.integrator.formulation == exc::plant::Formulation::augmented_baumgarte);
  const SceneBundle coarse = with("integrator.step", number(5e-3), SweepRun::open_loop);
  CHECK(coarse.scene.integrator.step == 5e-3);
  CHECK(coarse.scene.cycle == 5e-3);
  const SceneBundle clay = with("soil.stiffness", number(2.8e5), SweepRun::open_loop);
  CHECK(clay.scene.soil.stiffness.x() == doctest::Approx(2.8e5));
  CHECK(clay.scene.soil.damping.x() == doctest::Approx(nominal.scene.soil.damping.x() * 2));  // K x 4: B x 2
}

TEST_CASE("tools/sweep knobs: soil_blend runs from loose sand to stiff clay log-linearly, terrain_slope tilts both sides' ground through the dig and the path with it, path_speed divides the task's times, and the two path knobs compose in either order") {
  const SceneBundle& nominal = dig().nominal;
  // Soil between the presets (machine.md's loose sand K 20 kN/m, B 2.5 kN s/m; stiff clay 200, 9).
  const SceneBundle sand = with("soil_blend", number(0)), clay = with("soil_blend", number(1));
  CHECK(sand.scene.soil.stiffness.x() == doctest::Approx(2e4));
  CHECK(sand.scene.soil.damping.y() == doctest::Approx(2.5e3));
  CHECK(clay.scene.soil.stiffness.y() == doctest::Approx(2e5));
  CHECK(clay.scene.soil.damping.x() == doctest::Approx(9e3));
  CHECK(clay.scene.soil.mass.x() == doctest::Approx(200));
  const SceneBundle middle = with("soil_blend", number(0.5));
  CHECK(middle.scene.soil.stiffness.x() == doctest::Approx(std::sqrt(2e4 * 2e5)));  // geometric, not 110 kN/m
  CHECK(middle.scene.soil.damping.x() == doctest::Approx(std::sqrt(2.5e3 * 9e3)));
  CHECK(std::abs(middle.scene.soil.stiffness.x() / 7e4 - 1) < 0.1);  // within 10 % of loam's K
  CHECK(nominal.scene.soil.stiffness.x() == doctest::Approx(7e4));   // the nominal scene untouched

  // The ground rising 10 degrees away from the machine, through the dig's working area: the mean x of the
  // poses at or below the ground (6.8, 6.5, 5.6, 5.1 m: 6.0 m), where it keeps the nominal ground's height.
  const double rise = std::tan(10 * 3.14159265358979323846 / 180);
  const SceneBundle slope = with("terrain_slope", number(10));
  for (const exc::Terrain* ground : {&slope.firmware.terrain, &slope.scene.terrain}) {  // the site map and the plant's soil surface
    CHECK(ground->height_at(6.0) == doctest::Approx(0).epsilon(1e-12));
    CHECK(ground->height_at(7.0) == doctest::Approx(rise));
    CHECK(ground->height_at(5.0) == doctest::Approx(-rise));
  }
  // Every pose after the first keeps its depth below the local ground; the first (the approach in the
  // air, the initial state's inverse kinematics) stays where it was.
  const auto& tilted = slope.firmware.task.path;
  const auto& flat = nominal.firmware.task.path;
  REQUIRE(tilted.size() == flat.size());
  CHECK(tilted[0].pose.z == flat[0].pose.z);
  for (std::size_t i = 1; i < tilted.size(); ++i) {
    CAPTURE(i);
    CHECK(tilted[i].pose.x == flat[i].pose.x);
    CHECK(tilted[i].pose.z - slope.firmware.terrain.height_at(tilted[i].pose.x) ==
          doctest::Approx(flat[i].pose.z - nominal.firmware.terrain.height_at(flat[i].pose.x)));
  }
  CHECK(with("terrain_slope", number(-10)).firmware.terrain.height_at(7.0) == doctest::Approx(-rise));

  // The path run 1.25x as fast: every time and the run / 1.25.
  const SceneBundle fast = with("path_speed", number(1.25));
  CHECK(fast.firmware.task.end_time() == doctest::Approx(nominal.firmware.task.end_time() / 1.25));
  CHECK(fast.firmware.duration == doctest::Approx(nominal.firmware.duration / 1.25));
  CHECK(fast.scene.duration == fast.firmware.duration);  // the plant runs as long
  for (std::size_t i = 0; i < flat.size(); ++i) CHECK(fast.firmware.task.path[i].t == doctest::Approx(flat[i].t / 1.25));

  // Both on one case, in either order: the tilted heights at the faster times.
  for (const bool slope_first : {true, false}) {
    CAPTURE(slope_first);
    SceneChanges both(dig());
    const std::vector<std::pair<std::string, double>> order =
        slope_first ? std::vector<std::pair<std::string, double>>{{"terrain_slope", 10}, {"path_speed", 1.25}}
                    : std::vector<std::pair<std::string, double>>{{"path_speed", 1.25}, {"terrain_slope", 10}};
    for (const auto& [knob, x] : order) exc::sim::set_knob(SweepRun::closed_loop, knob, number(x), both);
    const SceneBundle b = both.read();
    for (std::size_t i = 0; i < flat.size(); ++i) {
      CHECK(b.firmware.task.path[i].t == doctest::Approx(fast.firmware.task.path[i].t));
      CHECK(b.firmware.task.path[i].pose.z == doctest::Approx(tilted[i].pose.z));
    }
    CHECK(b.firmware.duration == doctest::Approx(fast.firmware.duration));
  }

  // A joint-waypoint task: path_speed divides its waypoints' times; there is no path to tilt.
  const exc::sim::SceneSource free = exc::sim::load_scene_source(std::string(EXC_SOURCE_DIR) + "/scenes/free_motion.yaml");
  SceneChanges quick(free);
  exc::sim::set_knob(SweepRun::closed_loop, "path_speed", number(0.8), quick);
  const SceneBundle slow = quick.read();
  REQUIRE(slow.firmware.task.waypoint_times.size() == free.nominal.firmware.task.waypoint_times.size());
  for (std::size_t i = 0; i < slow.firmware.task.waypoint_times.size(); ++i)
    CHECK(slow.firmware.task.waypoint_times[i] == doctest::Approx(free.nominal.firmware.task.waypoint_times[i] / 0.8));
  SceneChanges tilt(free);
  CHECK_THROWS_WITH_AS(exc::sim::set_knob(SweepRun::closed_loop, "terrain_slope", number(5), tilt),
                       doctest::Contains("needs a task path"), std::exception);
}

TEST_CASE("tools/sweep knobs: docs/sweeps.md has a row for every named knob, and names no other") {
  const std::string doc = read_text_file(std::string(EXC_SOURCE_DIR) + "/docs/sweeps.md");
  const std::string start = "| run | knob | range | what it sets |";
  REQUIRE(doc.find(start) != std::string::npos);
  std::set<std::string> documented, declared;
  for (std::size_t line = doc.find('\n', doc.find(start)) + 1; doc.compare(line, 1, "|") == 0; line = doc.find('\n', line) + 1) {
    const std::size_t cell = doc.find('|', line + 1) + 1;  // the second cell: the knob, in backquotes
    const std::size_t open = doc.find('`', cell), close = doc.find('`', open + 1);
    if (open < doc.find('|', cell)) documented.insert(doc.substr(open + 1, close - open - 1));
  }
  for (const SweepRun run : {SweepRun::closed_loop, SweepRun::open_loop})
    for (const exc::sim::Knob& k : exc::sim::named_knobs(run)) declared.insert(k.name);
  CHECK(documented == declared);
}

TEST_CASE("tools/excavator-sim sweep refuses at load a value the scene's readers refuse, exit 2, naming the spec's line and the setting's range, and runs the boundary") {
  const exc::test::Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  const std::string head = "sweep:\n  scene: " + kDig + "\n  controllers: [pid]\n  duration: 0.05\n";
  struct Bad {
    std::string spec, at, field, reason;
  };
  // Before, delay_cycles took 0..100 and the plant read its sensors' 64-slot ring at a negative index.
  const std::vector<Bad> bad = {
      {head + "  variants:\n    - {name: late, delay_cycles: 64}\n", "64}", "sweep.variants[0].delay_cycles",
       "is 64; allowed: a whole number in [0, 63] (sensors.latency_cycles"},
      {head + "  grid:\n    delay_cycles: [0, 100]\n", "100]", "sweep.grid.delay_cycles[1]", "a whole number in [0, 63]"},
      {head + "  cases: 2\n  perturbations:\n    delay_cycles: [0, 100]\n", "100]", "sweep.perturbations.delay_cycles[1]",
       "a whole number in [0, 63]"},
      {head + "  grid:\n    sensors.position_noise: [0.5]\n", "0.5]", "sweep.grid.sensors.position_noise[0]",
       "allowed: a number in [0, 0.1]"},
      // Within the knob's own range, but the rates it scales leave theirs: the controller's reader refuses.
      {head + "  grid:\n    adaptation_scale: [1, 1.0e+6]\n", "1.0e+6]", "sweep.grid.adaptation_scale[1]",
       "controller.adaptation_rate[2]: is 1e+17; allowed range [0, 1e+16]"},  // the valves' derived 1e11 x 1e6
      {head + "  grid:\n    machine.hydraulics.bulk_modulus: [1.0e+3]\n", "1.0e+3]",
       "sweep.grid.machine.hydraulics.bulk_modulus[0]", "allowed: a number in [1e+07, 5e+09] Pa"},
      {head + "  grid:\n    sensors.latency: [1]\n", "[1]", "sweep.grid.sensors.latency", "is no knob"},
      // The generalisation sweep's knobs: their own ranges, and a path too fast for the actuators refused
      // by the firmware's effort check as the scene file's would be.
      {head + "  grid:\n    terrain_slope: [0, 50]\n", "50]", "sweep.grid.terrain_slope[1]", "allowed: a number in [-45, 45] deg"},
      {head + "  cases: 2\n  perturbations:\n    soil_blend: [0, 1.5]\n", "1.5]", "sweep.perturbations.soil_blend[1]",
       "allowed: a number in [0, 1]"},
      {head + "  grid:\n    path_speed: [1, 5]\n", "5]", "sweep.grid.path_speed[1]", "is 5, refused by the scene: "},
  };
  for (const Bad& b : bad) {
    CAPTURE(b.spec);
    std::ofstream(dir / "spec.yaml") << b.spec;
    const exc::test::Run r = run_sim("sweep " + (dir / "spec.yaml").string() + " --quiet --out x.jsonl");
    CAPTURE(r.err);
    CHECK(r.status == 2);
    const auto [line, column] = exc::test::place_of(b.spec, b.at);
    CHECK(r.err.find((dir / "spec.yaml").string() + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " +
                     b.field + ": ") != std::string::npos);
    CHECK(r.err.find(b.reason) != std::string::npos);
    CHECK_FALSE(fs::exists(r.dir / "x.jsonl"));  // no case ran
  }
  // The control: the ring's last slot is a valid delay, and the case runs with it.
  std::ofstream(dir / "spec.yaml") << head + "  variants:\n    - {name: late, delay_cycles: 63}\n";
  const exc::test::Run ok = run_sim("sweep " + (dir / "spec.yaml").string() + " --quiet --out x.jsonl");
  REQUIRE_MESSAGE(ok.status == 0, ok.err);
  const nlohmann::json line = nlohmann::json::parse(read_text_file(ok.dir / "x.jsonl"));
  CHECK(line["set"]["delay_cycles"] == 63);
  CHECK(line["pid"].contains("ok"));
}

TEST_CASE("tools/excavator-sim sweep reads a value the scene refuses alone with the grid's and the variants' values it runs with, and names the one it fails with") {
  // The free motion's path at 1.3x asks the swing for 84.5 kN m against 59.5: refused alone, taken
  // with the path's timing fitted (a flag: a choice of true and false for the sweep).
  const exc::test::Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  const std::string head = "sweep:\n  scene: " + std::string(EXC_SOURCE_DIR) +
                           "/scenes/free_motion.yaml\n  controllers: [pid]\n  duration: 0.05\n  cases: 2\n"
                           "  perturbations:\n    path_speed: [0.6, 1.3]\n";
  const auto sweep = [&](const std::string& rest) {
    std::ofstream(dir / "spec.yaml") << head + rest;
    return run_sim("sweep " + (dir / "spec.yaml").string() + " --quiet --out x.jsonl");
  };
  for (const std::string& fitted : {std::string("  grid:\n    task.efforts.fit_timing: [true]\n"),
                                    std::string("  variants:\n    - {name: fitted, task.efforts.fit_timing: true}\n")}) {
    CAPTURE(fitted);
    const exc::test::Run ok = sweep(fitted);
    REQUIRE_MESSAGE(ok.status == 0, ok.err);
    const std::string lines = read_text_file(ok.dir / "x.jsonl");
    CHECK(std::count(lines.begin(), lines.end(), '\n') == 2);
  }
  // One grid point without the fit: refused at the draw's end, naming the setting it was read with.
  const exc::test::Run unfitted = sweep("  grid:\n    task.efforts.fit_timing: [false, true]\n");
  CHECK(unfitted.status == 2);
  CHECK(unfitted.err.find("sweep.perturbations.path_speed[1]: is 1.3, refused by the scene with task.efforts.fit_timing = false: ") !=
        std::string::npos);
  CHECK(unfitted.err.find("the swing needs") != std::string::npos);
  // Without the grid, as before: refused by the scene alone.
  const exc::test::Run alone = sweep("");
  CHECK(alone.status == 2);
  CHECK(alone.err.find("sweep.perturbations.path_speed[1]: is 1.3, refused by the scene: ") != std::string::npos);
  // A value refused for itself is named at itself, not at a draw read beside it.
  const exc::test::Run bad_flag = sweep("  grid:\n    task.efforts.fit_timing: [maybe]\n");
  CHECK(bad_flag.status == 2);
  CHECK(bad_flag.err.find("sweep.grid.task.efforts.fit_timing[0]: is maybe, refused by the scene: ") != std::string::npos);
  CHECK(bad_flag.err.find("allowed values: true, false") != std::string::npos);
  CHECK_FALSE(fs::exists(bad_flag.dir / "x.jsonl"));
}

TEST_CASE("tools/excavator-sim sweep with paired_draws runs every grid point of a scene on the same draws and faults, and without it each case draws its own") {
  const exc::test::Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  const auto lines_of = [&](bool paired) {
    std::ofstream(dir / "spec.yaml") << "sweep:\n  scene: " + kDig + "\n  controllers: [pid]\n  duration: 0.05\n  cases: 3\n"
                                        "  paired_draws: " + std::string(paired ? "true" : "false") + "\n"
                                        "  perturbations: {position_noise: [0, 1.0e-4], model_mass: [-0.2, 0.2]}\n"
                                        "  faults: [sensor_jump, rock]\n"
                                        "  grid: {sensors.latency_cycles: [0, 1]}\n";
    const exc::test::Run r = run_sim("sweep " + (dir / "spec.yaml").string() + " --quiet --out x.jsonl");
    REQUIRE_MESSAGE(r.status == 0, r.err);
    std::map<int, nlohmann::json> by_case;
    std::istringstream in(read_text_file(r.dir / "x.jsonl"));
    for (std::string line; std::getline(in, line);) {
      const nlohmann::json j = nlohmann::json::parse(line);
      by_case[j["case"].get<int>()] = j;
    }
    REQUIRE(by_case.size() == 6);  // 2 grid points x 3 draws
    return by_case;
  };
  const auto paired = lines_of(true), unpaired = lines_of(false);
  for (int d = 0; d < 3; ++d) {
    CAPTURE(d);
    // Case d runs latency 0, case 3 + d latency 1.
    CHECK(paired.at(d)["set"]["sensors.latency_cycles"] == 0);
    CHECK(paired.at(3 + d)["set"]["sensors.latency_cycles"] == 1);
    for (const char* knob : {"position_noise", "model_mass"}) {
      CHECK(paired.at(d)[knob] == paired.at(3 + d)[knob]);
      CHECK(unpaired.at(d)[knob] != unpaired.at(3 + d)[knob]);
    }
    CHECK(paired.at(d)["fault"] == paired.at(3 + d)["fault"]);
    CHECK(unpaired.at(d)["fault"] != unpaired.at(3 + d)["fault"]);
  }
  // Different draws of one grid point still differ.
  CHECK(paired.at(0)["model_mass"] != paired.at(1)["model_mass"]);
}

TEST_CASE("tools/excavator-sim sweep refuses two knobs that write one setting whole (the later would undo the earlier), and takes knobs that compose") {
  const exc::test::Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  const std::string head = "sweep:\n  scene: " + kDig + "\n  controllers: [pid]\n  duration: 0.05\n  cases: 2\n";
  const std::vector<std::pair<std::string, std::string>> bad = {
      {"  perturbations: {soil_blend: [0, 1], soil_stiffness: [0.5, 2]}\n", "'soil_blend' and 'soil_stiffness' both write soil"},
      {"  perturbations: {terrain_slope: [-5, 5]}\n  grid: {terrain.height: [0.1]}\n", "both write terrain"},
      {"  perturbations: {model_mass: [-0.1, 0.1]}\n  grid: {firmware.machine.bodies.boom.mass: [2000]}\n",
       "both write firmware.machine.bodies"},
      {"  perturbations: {position_noise: [0, 1.0e-4]}\n  grid: {sensors.position_noise: [0]}\n", "both write sensors.position_noise"},
  };
  for (const auto& [knobs, reason] : bad) {
    CAPTURE(knobs);
    std::ofstream(dir / "spec.yaml") << head + knobs;
    const exc::test::Run r = run_sim("sweep " + (dir / "spec.yaml").string() + " --quiet --out x.jsonl");
    CHECK(r.status == 2);
    CHECK(r.err.find(reason) != std::string::npos);
    CHECK(r.err.find("choose one") != std::string::npos);
    CHECK_FALSE(fs::exists(r.dir / "x.jsonl"));
  }
  // The generalisation sweep's knobs compose: both path knobs, the soil between presets, the sensors.
  std::ofstream(dir / "spec.yaml") << head + "  perturbations: {soil_blend: [0, 1], terrain_slope: [-15, 15], path_speed: [0.7, 1.3], "
                                             "position_noise: [0, 3.0e-4], delay_cycles: [0, 3], model_mass: [-0.2, 0.2]}\n";
  const exc::test::Run ok = run_sim("sweep " + (dir / "spec.yaml").string() + " --quiet --out x.jsonl");
  REQUIRE_MESSAGE(ok.status == 0, ok.err);
  const std::string lines = read_text_file(ok.dir / "x.jsonl");
  CHECK(std::count(lines.begin(), lines.end(), '\n') == 2);  // both cases ran
}

TEST_CASE("tools/excavator-sim sweep and sweep-merge open each scene file and its machine file once per process, counted by strace") {
  const exc::test::Run setup = run_sim("--help");
  const fs::path dir = setup.dir;
  fs::copy_file(EXC_MACHINE_FILE, dir / "machine.yaml");
  std::ofstream(dir / "scene.yaml") << read_text_file(kDig) << "machine: machine.yaml\n";
  std::ofstream(dir / "spec.yaml") << "sweep:\n  scene: scene.yaml\n  controllers: [pid, adaptive]\n  duration: 0.05\n"
                                      "  cases: 3\n  perturbations: {model_mass: [-0.1, 0.1], delay_cycles: [0, 2]}\n"
                                      "  grid: {machine.hydraulics.bulk_modulus: [3.0e+8, 1.0e+9]}\n";
  for (const std::string command : {"sweep spec.yaml --quiet --out one.jsonl", "sweep-merge spec.yaml one.jsonl --out merged --no-charts"}) {
    CAPTURE(command);
    const std::string trace = (dir / "opens.txt").string();
    const std::string cmd = "cd '" + dir.string() + "' && strace -f -qq -e trace=open,openat -o '" + trace + "' " +
                            EXC_SIM_TOOL + " " + command + " > /dev/null 2>&1";
    REQUIRE_MESSAGE(std::system(cmd.c_str()) == 0, "strace (Debian package strace, installed by tools/install-deps test)");
    std::ifstream in(trace);
    int scene = 0, machine = 0, lines = 0;
    for (std::string line; std::getline(in, line); ++lines) {
      if (line.find("ENOENT") != std::string::npos) continue;
      scene += line.find("/scene.yaml\"") != std::string::npos;
      machine += line.find("/machine.yaml\"") != std::string::npos;
    }
    CHECK(lines > 10);  // the trace is real: the loader and libraries are opened too
    CHECK(scene == 1);
    CHECK(machine == 1);
  }
  CHECK(nlohmann::json::parse(read_text_file(dir / "merged" / "sweep.json"))["merged"] == 6);
}
