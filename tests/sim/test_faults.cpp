// A path the actuators cannot follow, as a user meets it through excavator-sim: a path fitted to the actuators runs to its end,
// the shipped scenes do not trip the tracking-error fault (but flow-based control where the swing
// moves), and a forced trip is in the log and the report with its code and its reason.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "control/laws/flow_position_control.hpp"
#include "exlcm/fault_t.hpp"
#include "harness/lockstep_run.hpp"
#include "sim_runs.hpp"

namespace fs = std::filesystem;
using namespace exc::test;  // Run, run_sim, edited_scene, read_text_file

namespace {

const std::string kFreeMotion = std::string(EXC_SOURCE_DIR) + "/scenes/free_motion.yaml";

// The shipped scenes whose swing moves on the hydraulic machine: there flow-based control lags the
// swing past its limit (below), and is left out of the default controllers.
const std::set<std::string> kSwingLags{"free_motion.yaml", "hold_swung_high.yaml", "truck_loading.yaml", "truck_clay_slope.yaml"};

// A saturating swing in a free-motion scene (2 rad in 2.5 s where it turns 0.4 rad in 2 s), with the
// task's `efforts:` mapping and any further edits.
fs::path fast_swing(const std::string& efforts, const std::string& stem,
                    std::vector<std::pair<std::string, std::string>> edits = {}, const std::string& scene = kFreeMotion) {
  edits.emplace_back("    - {t: 2.0, q: [0.4, 2.70, 2.60, 1.90]}", "    - {t: 2.5, q: [2.0, 2.70, 2.60, 1.90]}");
  edits.emplace_back("  type: joint_waypoints", "  type: joint_waypoints\n  efforts: " + efforts);
  return edited_scene(scene, edits, stem);
}

// The swing forced and left to run saturated to the end (the tracking-error fault out of the way)
// in `scene`, PID and adaptive; the summary.
nlohmann::json saturated_swing(const std::string& scene, const std::string& stem,
                               std::vector<std::pair<std::string, std::string>> edits = {}) {
  const std::string limits = "tracking_error_limit: [10, 10, 10, 10]";
  if (read_text_file(scene).find("\ncontroller:\n") != std::string::npos)
    edits.emplace_back("\ncontroller:\n", "\ncontroller:\n  " + limits + "\n");
  else
    edits.emplace_back("\ntask:\n", "\ncontroller: {" + limits + "}\ntask:\n");
  const fs::path edited = fast_swing("{check: false}", stem, edits, scene);
  const Run r = run_sim("run " + edited.string() + " --controller pid,adaptive --quiet --no-report --json summary.json");
  INFO(r.err);
  REQUIRE(r.status == 0);
  return nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
}

}  // namespace

TEST_CASE("tools/excavator-sim runs a too-fast swing fitted to the actuators end to end: the run's duration stretched with the path and said in the setup line, the task finished") {
  const fs::path scene = fast_swing("{fit_timing: true}", "fitted_swing");
  const exc::sim::SceneBundle bundle = exc::sim::load_scene_bundle(scene.string());
  const double scale = bundle.firmware.task.timing_scale;
  REQUIRE(scale > 2);
  // The 8 s run covered the 8 s path: it now covers the stretched one and the track delay after it.
  CHECK(bundle.scene.duration == bundle.firmware.duration);
  CHECK(bundle.firmware.duration >= 8 * scale + 0.05);
  // PID and adaptive (the flow-based law, without an acceleration feedforward, lags the swing at
  // its torque limit by the swing's 0.1 rad and stops).
  const Run r = run_sim("run " + scene.string() + " --controller pid,adaptive --quiet --no-report --json summary.json");
  INFO(r.out << r.err);
  CHECK(r.status == 0);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
  const std::string setup = j["setup"].get<std::string>();
  CHECK(setup.find("task timing scaled by " + std::to_string(scale).substr(0, 4)) != std::string::npos);
  CHECK(setup.find("the run's duration with it (8.1 s -> ") != std::string::npos);
  CHECK(r.out.find(setup) != std::string::npos);
  for (const char* c : {"pid", "adaptive"}) {
    INFO(c);
    CHECK(j[c]["ok"].get<bool>());
    CHECK(j[c]["task_finished"].get<bool>());
    CHECK(j[c]["task_finish_time"].get<double>() == doctest::Approx(8 * scale + 0.05).epsilon(2e-4));
    CHECK(j[c]["simulated_seconds"].get<double>() == doctest::Approx(bundle.firmware.duration).epsilon(1e-4));
  }
}

TEST_CASE("tools/excavator-sim: every shipped scene, for its full duration with each controller it runs by default, never goes to the safe state and exits 0, and flow-based control, left out of the defaults where the swing moves, stops there on the swing") {
  std::vector<fs::path> scenes;
  for (const auto& e : fs::directory_iterator(fs::path(EXC_SOURCE_DIR) / "scenes"))
    if (e.path().extension() == ".yaml") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  REQUIRE(scenes.size() >= 5);
  for (const fs::path& scene : scenes) {
    const exc::sim::SceneBundle bundle = exc::sim::load_scene_bundle(scene.string());
    const exc::control::ControllerConfig& cc = bundle.firmware.controller;
    REQUIRE_FALSE(cc.law_given);  // no shipped scene picks a controller: each runs the defaults
    // The defaults (docs/control.md): pid and adaptive, and flow on a valve-commanded scene whose
    // task holds the swing; where it moves, flow is left out and the run says why.
    const bool valves = cc.command_interface == exc::control::CommandInterface::valve;
    const bool flow_lags = kSwingLags.count(scene.filename().string()) > 0;
    if (valves) CHECK(exc::control::flow_law_fits(bundle.firmware.task) == !flow_lags);
    std::vector<std::string> controllers{"pid", "adaptive"};
    if (valves && !flow_lags) controllers.push_back("flow");
    const Run r = run_sim("run " + scene.string() + " --quiet --no-report --json summary.json");
    INFO(scene.filename().string() << ": " << r.err);
    CHECK(r.status == 0);
    CHECK((r.err.find("flow left out of the default controllers: the task moves the swing") != std::string::npos) ==
          (valves && flow_lags));
    const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
    CHECK(j.contains("flow") == (valves && !flow_lags));
    if (valves && flow_lags) {
      // Flow-based control's known limit (flow_position_control.hpp): with no model it cannot
      // accelerate the swing's inertia through its soft oil column in time, lags past the swing's
      // limit where the swing moves, and the firmware stops it there, on the swing alone.
      const Run f = run_sim("run " + scene.string() + " --controller flow --quiet --no-report --json flow.json");
      CHECK(f.status == 1);
      const nlohmann::json jf = nlohmann::json::parse(read_text_file(f.dir / "flow.json"));
      CHECK(jf["flow"]["safe_stops"].get<int>() == 1);
      const std::string failure = jf["flow"]["failure"].get<std::string>();
      MESSAGE(scene.filename().string() << " flow: " << failure);
      CHECK(failure.find("tracking error: swing ") != std::string::npos);
    }
    for (const std::string& c : controllers) {
      INFO(c);
      REQUIRE(j.contains(c));
      CHECK(j[c]["safe_stops"].get<int>() == 0);
      CHECK(j[c]["ok"].get<bool>());
      CHECK(j[c]["simulated_seconds"].get<double>() == doctest::Approx(bundle.firmware.duration).epsilon(1e-6));
      // How close each came: its worst true error as a share of its joint's limit.
      double share = 0;
      const char* joints[4] = {"swing", "boom", "arm", "bucket"};
      for (int k = 0; k < 4; ++k)
        share = std::max(share, j[c]["max_error"][joints[k]].get<double>() / cc.supervisor.tracking_error_limit[k]);
      MESSAGE(scene.filename().string() << " " << c << ": worst error " << share * 100 << " % of its limit");
      CHECK(share < 1);
    }
  }
}

TEST_CASE("tools/excavator-sim: a forced trip of the tracking-error fault is on EXC_FAULT (code 3, the transition and the reason) and in report.md's status row") {
  const fs::path scene = fast_swing("{check: false}", "tripped_swing");
  const Run r = run_sim("run " + scene.string() + " --controller pid --quiet --out out --json summary.json");
  INFO(r.err);
  CHECK(r.status == 1);
  const nlohmann::json j = nlohmann::json::parse(read_text_file(r.dir / "summary.json"));
  const std::string failure = j["pid"]["failure"].get<std::string>();
  const std::string reason = "tracking error: swing ";
  REQUIRE(failure.find(reason) != std::string::npos);
  // The log: one fault_t raised on the pid run's channel, the code, the transition and the reason the
  // summary names.
  lcm::LogFile log((r.dir / "out" / "run.lcm").string(), "r");
  REQUIRE(log.good());
  int raised = 0;
  while (const lcm::LogEvent* e = log.readNextEvent()) {
    if (e->channel != "EXC_FAULT/pid") continue;
    exlcm::fault_t f;
    REQUIRE(f.decode(e->data, 0, e->datalen) > 0);
    if (!f.active) continue;
    ++raised;
    const std::string text(reinterpret_cast<const char*>(f.text));
    MESSAGE(f.utime << " us: code " << f.code << ", " << text);
    CHECK(f.code == 3);
    CHECK(f.severity == 2);
    CHECK(text.rfind("track -> safe_stop: fault: " + reason, 0) == 0);
    const std::string named = text.substr(text.find(reason));
    CHECK(failure.find(named) != std::string::npos);
  }
  CHECK(raised == 1);
  // The report's status row carries the whole reason.
  const std::string report = read_text_file(r.dir / "out" / "report" / "report.md");
  CHECK(report.find("| status | FAILED: " + failure + " |") != std::string::npos);
}

TEST_CASE("tools/excavator-sim: in a saturated swing with no soil the adaptive law's arm and bucket errors are within 1.5x of PID's, tens of times PID's only where the firmware takes itself to be in soil") {
  // The tip stays above the ground (docs/control.md, "Saturation and the soil term"): no contact is
  // estimated, so the law has no soil term and no update (its estimates end where they began): it
  // is the PD computed torque, PID's law without the integral. On the paper's force actuators and
  // through the valves.
  const std::string paper = std::string(EXC_SOURCE_DIR) + "/scenes/paper_free_motion.yaml";
  for (const std::string& scene : {paper, kFreeMotion}) {
    const nlohmann::json j = saturated_swing(scene, "saturated_" + fs::path(scene).stem().string());
    for (const char* c : {"pid", "adaptive"}) CHECK(j[c]["max_error"]["swing"].get<double>() > 1.5);  // saturated
    for (const std::string joint : {"arm", "bucket"}) {
      const double ratio = j["adaptive"]["rms_error"][joint].get<double>() / j["pid"]["rms_error"][joint].get<double>();
      MESSAGE(fs::path(scene).filename().string() << ", no soil: adaptive / PID on the " << joint << " " << ratio);
      CHECK(ratio < 1.5);
    }
    CHECK(j["adaptive"]["theta_hat"] == nlohmann::json({{"M_x", 100.0}, {"B_x", 2000.0}, {"K_x", 30000.0},
                                                        {"M_z", 100.0}, {"B_z", 2000.0}, {"K_z", 30000.0}}));
  }
  // Through the valves with the firmware's terrain 4 m up: every tip position is "in soil" to the
  // firmware, none to the plant (no soil), and the soil term pulls the tip toward an anchor with
  // estimates the update cannot take below their bounds (theta_min). The paper's law (no observer):
  // arm and bucket tens of times PID's. The defaults' observer measures that no such force acts and
  // takes the wrong term back out: a few times PID's at most.
  const nlohmann::json buried =
      saturated_swing(kFreeMotion, "buried_swing", {{"terrain: {height: 0.0}", "terrain: {height: 4.0}"}});
  const nlohmann::json buried_paper = saturated_swing(
      kFreeMotion, "buried_swing_paper",
      {{"terrain: {height: 0.0}", "terrain: {height: 4.0}"},
       {"\ncontroller:\n", "\ncontroller:\n  external_force: {observer: false, identification_memory: 0}\n"}});
  for (const std::string joint : {"arm", "bucket"}) {
    const double ratio = buried["adaptive"]["rms_error"][joint].get<double>() / buried["pid"]["rms_error"][joint].get<double>();
    const double paper = buried_paper["adaptive"]["rms_error"][joint].get<double>() /
                         buried_paper["pid"]["rms_error"][joint].get<double>();
    MESSAGE("no soil, the firmware's terrain above the tip: adaptive / PID on the " << joint << " " << ratio
                                                                                      << ", the paper's law " << paper);
    CHECK(paper > 10);
    CHECK(ratio < 5);
  }
}

TEST_CASE("firmware/node: a machine not standing where its task starts is stopped in the task's first cycle, the fault saying so") {
  const std::string start = "  q_a: [0.0, 2.5021, 2.9255, 1.7856]";
  // 1 rad of swing away from the path's first point: stopped at once, named as the start.
  const fs::path far = edited_dig(start, "  q_a: [1.0, 2.5021, 2.9255, 1.7856]", "far_start");
  const Run r = run_sim("run " + far.string() + " --controller pid --no-report --quiet --out out");
  INFO(r.out << r.err);
  CHECK(r.status == 1);
  // The valve machine's default swing limit: 5 x the 7.8 mrad it reaches (controller_config.hpp).
  CHECK(r.out.find("tracking error at the task's start: swing 1.0000 rad from its first point > limit 0.0390") !=
        std::string::npos);
  // The control: 0.02 rad away, within the limit, the law pulls it onto the path and the task runs.
  const fs::path near = edited_dig(start, "  q_a: [0.02, 2.5021, 2.9255, 1.7856]", "near_start");
  const Run n = run_sim("run " + near.string() + " --controller pid --no-report --quiet --out out");
  INFO(n.out << n.err);
  CHECK(n.status == 0);
  CHECK(n.out.find("task's start") == std::string::npos);
}
