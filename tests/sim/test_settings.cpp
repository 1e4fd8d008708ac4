// Settings, seen from outside: each enumeration's names in the docs are exactly its table's; the
// effective configuration of a scene loads back to the same configuration and to the same run; the
// firmware prints its own sections the way the simulator sees them.
#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <sys/wait.h>
#include <unistd.h>
#include <vector>

#include "control/controller_config.hpp"
#include "control/controller_registry.hpp"
#include "control/task/task.hpp"
#include "harness/lockstep_run.hpp"
#include "sim_plant/integration_methods.hpp"
#include "settings/section_reader.hpp"
#include "sweep_tables.hpp"
#include "scratch_files.hpp"
#include "text_file.hpp"

namespace fs = std::filesystem;
using exc::test::read_text_file;

namespace {

// The backquoted words of one cell (column, 1-based) of the markdown table row whose first cell is
// `field` in backquotes.
std::set<std::string> names_in_row(const std::string& doc, const std::string& field, int column) {
  const std::string text = read_text_file(std::string(EXC_SOURCE_DIR) + "/docs/" + doc);
  const std::string start = "| `" + field + "` |";
  const auto at = text.find("\n" + start);
  REQUIRE_MESSAGE(at != std::string::npos, doc << " has no row for " << field);
  const std::string row = text.substr(at + 1, text.find('\n', at + 1) - at - 1);
  std::size_t cell_start = 0;
  for (int c = 0; c < column; ++c) cell_start = row.find('|', cell_start) + 1;
  const std::string cell = row.substr(cell_start, row.find('|', cell_start) - cell_start);
  std::set<std::string> names;
  for (std::size_t p = cell.find('`'); p != std::string::npos; p = cell.find('`', cell.find('`', p + 1) + 1))
    names.insert(cell.substr(p + 1, cell.find('`', p + 1) - p - 1));
  return names;
}

template <typename Table>
std::set<std::string> names_of(const Table& table) {
  const std::vector<std::string> v = table.name_list();
  return {v.begin(), v.end()};
}

struct Run {
  int status = -1;
  std::string out, err;
};

Run run(const std::string& command, const fs::path& dir) {
  const std::string cmd = "cd '" + dir.string() + "' && " + command + " > out.txt 2> err.txt";
  const int raw = std::system(cmd.c_str());
  Run r;
  r.status = WIFEXITED(raw) ? WEXITSTATUS(raw) : -1;
  r.out = read_text_file(dir / "out.txt");
  r.err = read_text_file(dir / "err.txt");
  return r;
}

fs::path fresh_dir(const std::string& name) {
  return exc::test::scratch_dir(fs::path(EXC_BINARY_DIR) / "tests" / "sim" / (name + "_" + std::to_string(getpid())));
}

const char* const kScenes[] = {"dig.yaml", "free_motion.yaml", "truck_loading.yaml"};

}  // namespace

TEST_CASE("tools/settings: each enumerated field's row in the docs lists exactly its table's names") {
  using namespace exc;
  CHECK(names_in_row("scene-schema.md", "soil.preset", 2) == names_of(plant::kSoilPresets));
  CHECK(names_in_row("scene-schema.md", "actuators.fidelity", 2) == names_of(plant::actuator_fidelities()));
  CHECK(names_in_row("scene-schema.md", "integrator.method", 2) == names_of(plant::integration_methods()));
  CHECK(names_in_row("scene-schema.md", "integrator.formulation", 2) == names_of(plant::kFormulations));
  CHECK(names_in_row("scene-schema.md", "integrator.pressure_method", 2) == names_of(plant::kPressureMethods));
  CHECK(names_in_row("scene-schema.md", "controller.type", 2) == names_of(control::controller_registry()));
  CHECK(names_in_row("scene-schema.md", "controller.regressor_acceleration", 2) ==
        names_of(control::kRegressorAccelerations));
  CHECK(names_in_row("scene-schema.md", "task.type", 2) == names_of(control::kTaskTypes));
  CHECK(names_in_row("scene-schema.md", "controller.command_interface", 2) == names_of(control::kCommandInterfaces));
  CHECK(names_in_row("control.md", "command_interface", 3) == names_of(control::kCommandInterfaces));
  CHECK(names_in_row("control.md", "type", 3) == names_of(control::controller_registry()));
  CHECK(names_in_row("control.md", "regressor_acceleration", 3) == names_of(control::kRegressorAccelerations));
  CHECK(names_in_row("sweeps.md", "sweep.controllers", 2) == names_of(control::controller_registry()));
  CHECK(names_in_row("sweeps.md", "sweep.faults", 2) == names_of(sim::kFaultKinds));
  CHECK(names_in_row("sweeps.md", "sweep.run", 2) == names_of(sim::kSweepRuns));
  CHECK(names_in_row("sweeps.md", "sweep.record", 2) == names_of(sim::kSweepRecords));
}

TEST_CASE("tools/settings: a shipped scene's effective configuration fills every default and loads back to itself") {
  const fs::path dir = fresh_dir("effective");
  for (const char* name : kScenes) {
    CAPTURE(std::string(name));
    const exc::sim::SceneBundle a = exc::sim::load_scene_bundle(std::string(EXC_SOURCE_DIR) + "/scenes/" + name);
    const std::string dump = exc::settings::emit(a.effective);
    // Both sides' sections, with the defaults the file does not give.
    for (const char* key : {"name", "terrain", "duration", "soil", "initial_state", "actuators", "integrator", "sensors",
                            "checks", "controller", "task"})
      CHECK_MESSAGE(a.effective[key].IsDefined(), key);
    CHECK(a.effective["integrator"]["implicit_tolerance"].IsDefined());
    CHECK(a.effective["checks"]["pressure_check_margin"].IsDefined());
    CHECK(a.effective["controller"]["slotine_li"]["kd"].IsDefined());
    CHECK(a.effective["task"]["efforts"]["soil_margin"].IsDefined());
    const fs::path copy = dir / name;
    std::ofstream(copy) << dump;
    const exc::sim::SceneBundle b = exc::sim::load_scene_bundle(copy.string());
    CHECK(exc::settings::emit(b.effective) == dump);
    // The same configuration, to the bit.
    CHECK(b.firmware.controller.pid.gains.kp == a.firmware.controller.pid.gains.kp);
    CHECK(b.firmware.controller.adaptation.rate == a.firmware.controller.adaptation.rate);
    CHECK(b.firmware.task.trajectory.times() == a.firmware.task.trajectory.times());
    CHECK(b.firmware.task.trajectory.points() == a.firmware.task.trajectory.points());
    CHECK(b.scene.q_a0 == a.scene.q_a0);
    CHECK(b.scene.soil.stiffness == a.scene.soil.stiffness);
    CHECK(b.scene.sensors.position_quantum == a.scene.sensors.position_quantum);
  }
}

TEST_CASE("tools/settings: a scene naming its machine dumps the machine's absolute path, which loads from anywhere") {
  const fs::path dir = fresh_dir("machine_path");
  std::string text = read_text_file(std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml");
  fs::copy_file(EXC_MACHINE_FILE, dir / "m.yaml");
  std::ofstream(dir / "scene.yaml") << "machine: m.yaml\n" << text;
  const exc::sim::SceneBundle a = exc::sim::load_scene_bundle((dir / "scene.yaml").string());
  const std::string machine = a.effective["machine"].as<std::string>();
  CHECK(machine == fs::absolute(dir / "m.yaml").lexically_normal().string());
  fs::create_directories(dir / "elsewhere");
  std::ofstream(dir / "elsewhere" / "dump.yaml") << exc::settings::emit(a.effective);
  const exc::sim::SceneBundle b = exc::sim::load_scene_bundle((dir / "elsewhere" / "dump.yaml").string());
  CHECK(b.scene.machine_file == machine);
  CHECK(b.firmware.machine_file == machine);
  CHECK(b.scene.machine.hydraulics.pump_flow == a.scene.machine.hydraulics.pump_flow);
}

TEST_CASE("tools/excavator-sim config prints the effective configuration, run writes it, and a run of it gives the same figures to the bit") {
  const fs::path dir = fresh_dir("config_run");
  const std::string dig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";
  const Run config = run(std::string(EXC_SIM_TOOL) + " config " + dig, dir);
  REQUIRE_MESSAGE(config.status == 0, config.err);
  std::ofstream(dir / "dumped.yaml") << config.out;
  const Run original = run(std::string(EXC_SIM_TOOL) + " run " + dig +
                               " --duration 2 --quiet --no-report --out original --json original.json", dir);
  REQUIRE_MESSAGE(original.status == 0, original.err);
  const Run dumped = run(std::string(EXC_SIM_TOOL) + " run dumped.yaml --duration 2 --quiet --no-report --out dumped --json dumped.json", dir);
  REQUIRE_MESSAGE(dumped.status == 0, dumped.err);
  // run writes what config prints.
  CHECK(read_text_file(dir / "original" / "effective.yaml") == config.out);
  CHECK(read_text_file(dir / "dumped" / "effective.yaml") == config.out);
  const nlohmann::json a = nlohmann::json::parse(read_text_file(dir / "original.json"));
  const nlohmann::json b = nlohmann::json::parse(read_text_file(dir / "dumped.json"));
  for (const char* c : {"pid", "adaptive"}) {
    CAPTURE(c);
    REQUIRE(a[c]["rms_error"]["bucket"].get<double>() > 0);
    CHECK(a[c]["rms_error"] == b[c]["rms_error"]);  // JSON numbers: every digit of the double
    CHECK(a[c]["max_error"] == b[c]["max_error"]);
    CHECK(a[c]["tracking"] == b[c]["tracking"]);  // as the firmware measured it
    CHECK(a[c]["theta_hat"] == b[c]["theta_hat"]);
    CHECK(a[c]["peak_soil_force"] == b[c]["peak_soil_force"]);
  }
  const Run bad = run(std::string(EXC_SIM_TOOL) + " config /nonexistent.yaml", dir);
  CHECK(bad.status == 2);
  CHECK(bad.err.find("/nonexistent.yaml: cannot open the file") != std::string::npos);
}

TEST_CASE("tools/excavator-firmware --print-config prints the firmware's sections as excavator-sim config does") {
  const fs::path dir = fresh_dir("firmware_config");
  const std::string dig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";
  const Run fw = run(std::string(EXC_FIRMWARE_TOOL) + " --print-config --scene " + dig, dir);
  REQUIRE_MESSAGE(fw.status == 0, fw.err);
  const Run sim = run(std::string(EXC_SIM_TOOL) + " config " + dig, dir);
  REQUIRE(sim.status == 0);
  const YAML::Node f = YAML::Load(fw.out), s = YAML::Load(sim.out);
  std::set<std::string> keys;
  for (const auto& kv : f) keys.insert(kv.first.Scalar());
  CHECK(keys == std::set<std::string>{"name", "description", "terrain", "duration", "controller", "task"});
  for (const std::string& k : keys) CHECK_MESSAGE(exc::settings::emit(f[k]) == exc::settings::emit(s[k]), k);
}

TEST_CASE("tools/excavator-firmware and excavator-plant --print-config name a misspelt key of the plant's sections, and of the firmware's, with its file, line and the key it nearly spells (the firmware leaves their values to the plant and says so), and the help texts say what the programs do") {
  const fs::path dir = fresh_dir("plant_config");
  const std::string dig = std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml";
  // A misspelt key in the plant's soil section.
  std::string misspelt = read_text_file(dig);
  const auto soil = misspelt.find("soil: {preset: loam}");
  REQUIRE(soil != std::string::npos);
  misspelt.replace(soil, 20, "soil: {presett: loam}");
  std::ofstream(dir / "misspelt.yaml") << misspelt;
  // Where it is, counted in the file's text.
  const auto typo = misspelt.find("presett");
  const std::string line = std::to_string(1 + std::count(misspelt.begin(), misspelt.begin() + static_cast<long>(typo), '\n'));
  const std::string column = std::to_string(typo - misspelt.rfind('\n', typo));
  const std::string expected = "misspelt.yaml:" + line + ":" + column + ": soil.presett: unknown key; did you mean preset?";
  for (const char* tool : {EXC_FIRMWARE_TOOL, EXC_PLANT_TOOL}) {
    const Run r = run(std::string(tool) + " --print-config --scene misspelt.yaml", dir);
    INFO(tool, ": ", r.err);
    CHECK(r.status == 2);
    CHECK(r.out.empty());
    CHECK(r.err.find(expected) != std::string::npos);
  }
  // And the other way round: a misspelt key of the firmware's controller section is named by both
  // programs too, the plant reading those sections as the firmware does.
  std::string fw_typo = read_text_file(dig);
  const auto iface = fw_typo.find("  command_interface:");
  REQUIRE(iface != std::string::npos);
  fw_typo.replace(iface, 20, "  comand_interface:");
  std::ofstream(dir / "fw_typo.yaml") << fw_typo;
  const std::string fw_line = std::to_string(1 + std::count(fw_typo.begin(), fw_typo.begin() + static_cast<long>(iface), '\n'));
  const std::string fw_expected = "fw_typo.yaml:" + fw_line + ":3: controller.comand_interface: unknown key; did you mean command_interface?";
  for (const char* tool : {EXC_FIRMWARE_TOOL, EXC_PLANT_TOOL}) {
    const Run r = run(std::string(tool) + " --print-config --scene fw_typo.yaml", dir);
    INFO(tool, ": ", r.err);
    CHECK(r.status == 2);
    CHECK(r.out.empty());
    CHECK(r.err.find(fw_expected) != std::string::npos);
  }
  // The shipped scene: the firmware prints its sections and says the plant's values are the plant's to check.
  const Run fw = run(std::string(EXC_FIRMWARE_TOOL) + " --print-config --scene " + dig, dir);
  CHECK(fw.status == 0);
  CHECK(fw.err.find("the plant's (soil") != std::string::npos);
  CHECK(fw.err.find("checked for unknown keys only") != std::string::npos);
  CHECK(fw.err.find("excavator-plant --print-config --scene " + dig) != std::string::npos);
  // The control: the shipped scene's plant sections, defaults filled in, as excavator-sim config prints them.
  const Run good = run(std::string(EXC_PLANT_TOOL) + " --print-config --scene " + dig, dir);
  REQUIRE_MESSAGE(good.status == 0, good.err);
  CHECK(good.err.empty());
  const Run sim = run(std::string(EXC_SIM_TOOL) + " config " + dig, dir);
  const YAML::Node p = YAML::Load(good.out), s = YAML::Load(sim.out);
  for (const char* k : {"soil", "actuators", "sensors"}) CHECK_MESSAGE(exc::settings::emit(p[k]) == exc::settings::emit(s[k]), k);
  // Help: where the vcan set-up is described, the defaults shown; the operator's keep-alive is many frames.
  const Run plant_help = run(std::string(EXC_PLANT_TOOL) + " --help", dir);
  CHECK(plant_help.out.find("docs/vcan.md") != std::string::npos);
  CHECK(plant_help.out.find("see README") == std::string::npos);
  CHECK(plant_help.out.find("500") != std::string::npos);  // --silence-ms's default
  const Run operator_help = run(std::string(EXC_OPERATOR_TOOL) + " --help", dir);
  CHECK(operator_help.out.find("sends one operator command") == std::string::npos);
  CHECK(operator_help.out.find("one every --period for keep-alive") != std::string::npos);
}

TEST_CASE("tools/excavator-firmware and excavator-plant check the scene before the bus: a bad scene on a CAN interface that cannot be opened is the scene's error, exit 2") {
  const fs::path dir = fresh_dir("scene_before_bus");
  const std::string scenes = std::string(EXC_SOURCE_DIR) + "/scenes/";
  std::string misspelt = read_text_file(scenes + "dig.yaml");
  const auto soil = misspelt.find("soil: {preset: loam}");
  REQUIRE(soil != std::string::npos);
  misspelt.replace(soil, 20, "soil: {presett: loam}");
  std::ofstream(dir / "misspelt.yaml") << misspelt;
  // No interface of this name exists (and on a kernel without CAN none can be opened at all).
  const std::string bus = " --can exc-no-such-bus0 --startup-timeout 1";
  struct Case {
    std::string command, error;
  };
  const Case cases[] = {
      {std::string(EXC_FIRMWARE_TOOL) + bus + " --scene misspelt.yaml", "soil.presett: unknown key; did you mean preset?"},
      {std::string(EXC_PLANT_TOOL) + bus + " --scene misspelt.yaml", "soil.presett: unknown key; did you mean preset?"},
      // A law the scene's command interface cannot carry (paper_dig actuates efforts).
      {std::string(EXC_FIRMWARE_TOOL) + bus + " --scene " + scenes + "paper_dig.yaml --controller flow",
       "flow commands the valves' flow: it needs command_interface: valve"},
      // A stuck spool on a machine without valves (paper_dig's actuators are force actuators).
      {std::string(EXC_PLANT_TOOL) + bus + " --scene " + scenes + "paper_dig.yaml --stuck-spool boom",
       "--stuck-spool needs the hydraulic machine"},
  };
  for (const Case& c : cases) {
    const Run r = run(c.command, dir);
    INFO(c.command, "\n", r.err);
    CHECK(r.status == 2);
    CHECK(r.err.find(c.error) != std::string::npos);
    CHECK(r.err.find("exc-no-such-bus0") == std::string::npos);
  }
  // The control: a good scene gets as far as the bus, and is refused there, naming it.
  for (const char* tool : {EXC_FIRMWARE_TOOL, EXC_PLANT_TOOL}) {
    const Run r = run(std::string(tool) + bus + " --scene " + scenes + "dig.yaml", dir);
    INFO(tool, ": ", r.err);
    CHECK(r.status != 0);
    CHECK(r.status != 2);
    CHECK(r.err.find("exc-no-such-bus0") != std::string::npos);
  }
}
