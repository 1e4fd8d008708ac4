// A sweep's runs: a case's scene and settings made from its draws and set values, each controller
// through run_lockstep, one JSON line per case into the shard's file.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <stdexcept>

#include "control/controller_kinds.hpp"
#include "fault_campaign.hpp"
#include "output_file.hpp"
#include "run_report.hpp"
#include "sweep.hpp"

namespace exc::sim {
namespace {

namespace fs = std::filesystem;

Vec4 joints_of(const SweepValue& v) {
  return v.type == SweepValue::Type::joints ? Vec4(v.joints[0], v.joints[1], v.joints[2], v.joints[3])
                                            : Vec4::Constant(v.number);
}

void scale_model_masses(SceneBundle& b, double scale) {
  for (BodyInertia& body : b.firmware.machine.bodies) {
    body.mass *= scale;
    body.inertia *= scale;
  }
}

// One knob's value into the scene (the plant's sections) or the firmware's settings.
void apply_knob(SceneBundle& b, const std::string& knob, const SweepValue& v) {
  control::ControllerConfig& cc = b.firmware.controller;
  const double x = v.number;
  if (knob == "model_mass") scale_model_masses(b, 1 + x);
  else if (knob == "soil_stiffness") b.scene.soil.stiffness *= x;
  else if (knob == "position_noise") b.scene.sensors.position_noise = joints_of(v);
  else if (knob == "velocity_noise") b.scene.sensors.velocity_noise = joints_of(v);
  else if (knob == "delay_cycles") b.scene.sensors.latency_cycles = static_cast<int>(std::lround(x));
  else if (knob == "gain_scale") {
    // omega_n of the error dynamics x value (excavator-bench's gain axis).
    cc.gains.kp *= x * x;
    cc.gains.kv *= x;
    cc.gains.ki *= x * x * x;
    cc.sl_lambda *= x;
    cc.sl_kd *= x;
  } else if (knob == "adaptation_scale") {
    cc.adaptation_rate *= x;
    cc.sl_adaptation_rate *= x;
  } else if (knob == "controller.valves.force_time_constant") cc.valves.force_time_constant = x;
  else if (knob == "controller.valves.position_gain") cc.valves.position_gain = joints_of(v);
  else if (knob == "machine.hydraulics.valve_time_constant") b.scene.machine.hydraulics.valve_time_constant = x;
  else if (knob == "machine.hydraulics.bulk_modulus") b.scene.machine.hydraulics.bulk_modulus = x;
  else throw std::invalid_argument("sweep: the closed loop takes no knob '" + knob + "'");
}

const SceneBundle& cached_scene(const std::string& path) {
  static std::map<std::string, SceneBundle> scenes;  // one reading per scene file and process
  auto it = scenes.find(path);
  if (it == scenes.end()) it = scenes.emplace(path, load_scene_bundle(path)).first;
  return it->second;
}

RunRecord run_one(const SceneBundle& nominal, const SweepSpec& spec, const SweepCase& c, const std::string& controller,
                  const SweepSetting* searched) {
  SceneBundle b = nominal;
  // The draws the spec perturbs (an absent range leaves the scene's value).
  if (spec.model_mass.given) scale_model_masses(b, 1 + c.model_mass);
  if (spec.soil_stiffness.given) b.scene.soil.stiffness *= c.soil_stiffness;
  if (spec.position_noise.given) b.scene.sensors.position_noise = Vec4::Constant(c.position_noise);
  if (spec.delay_cycles.given) b.scene.sensors.latency_cycles = c.delay_cycles;
  for (const SweepSetting& s : c.set) apply_knob(b, s.first, s.second);
  if (searched) apply_knob(b, searched->first, searched->second);
  LockstepOptions o;
  o.controller = *control::kControllerKinds.named(controller);
  o.duration = spec.duration;
  o.stop_at_safe_state = spec.stop_at_safe_state;
  o.fault = fault_schedule(c, spec.seed);
  return run_lockstep(b.scene, b.firmware, o);
}

}  // namespace

RunRecord run_sweep_case(const SceneBundle& nominal, const SweepSpec& spec, const SweepCase& c,
                         const std::string& controller) {
  return run_one(nominal, spec, c, controller, nullptr);
}

nlohmann::json record_json(const RunRecord& r, const app::FirmwareSettings& firmware) {
  nlohmann::json run = {{"ok", r.ok},
                        {"rms_error", tracked_per_joint(r, r.rms_error)},
                        {"max_error", tracked_per_joint(r, r.max_error)}};
  if (!r.ok) run["failure"] = r.failure;
  run.update(run_outcome(r, firmware));  // the outcome the campaign counts, and its times
  run["simulated_seconds"] = r.simulated_seconds;
  if (r.hydraulic) run["pressure"] = {{"min", r.min_pressure}, {"max", r.peak_pressure}};
  return run;
}

nlohmann::json run_closed_loop_case(const SweepSpec& spec, const SweepCase& c) {
  const SceneBundle& nominal = cached_scene(spec.scenes[static_cast<std::size_t>(c.scene)]);
  nlohmann::json line = {{"case", c.id},
                         {"model_mass", c.model_mass},
                         {"soil_stiffness", c.soil_stiffness},
                         {"position_noise", c.position_noise},
                         {"delay_cycles", c.delay_cycles}};
  if (spec.scenes.size() > 1) line["scene"] = nominal.name;
  if (c.variant >= 0) line["variant"] = spec.variants[static_cast<std::size_t>(c.variant)].name;
  if (!c.set.empty()) {
    line["set"] = nlohmann::json::object();
    for (const SweepSetting& s : c.set) line["set"][s.first] = s.second.to_json();
  }
  if (c.fault != "none")
    line["fault"] = {{"kind", c.fault}, {"start", c.fault_start}, {"duration", c.fault_duration},
                     {"joint", c.fault_joint}, {"magnitude", c.fault_magnitude}};
  for (const std::string& name : spec.controllers) {
    if (spec.search.knob.empty()) {
      line[name] = record_json(run_one(nominal, spec, c, name, nullptr), nominal.firmware);
      continue;
    }
    // The search: the first value (in the spec's order) whose run passes; the failure of the one before.
    nlohmann::json run = {{"ok", false}, {"search_value", nullptr}};
    for (const SweepValue& v : spec.search.values) {
      const SweepSetting s{spec.search.knob, v};
      const RunRecord r = run_one(nominal, spec, c, name, &s);
      if (r.ok) {
        const std::string before = run.value("failure", "");
        run = record_json(r, nominal.firmware);
        run["search_value"] = v.to_json();
        if (!before.empty()) run["failure_before"] = before;
        break;
      }
      run["failure"] = r.failure;
    }
    line[name] = run;
  }
  return line;
}

int run_sweep_shard(const SweepSpec& spec, int shard, int shards, const fs::path& out, bool progress,
                    const SweepRunner& runner) {
  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());
  std::ofstream file = output::open_file(out);
  // A fault the scenes cannot take (pump_loss without the hydraulic machine) before any run.
  if (!spec.faults.empty())
    for (const std::string& scene : spec.scenes) check_faults_fit(spec.faults, cached_scene(scene));
  int done = 0;
  const int total = spec.total_cases();
  for (int id = shard; id < total; id += shards) {
    nlohmann::json line = runner(spec, sweep_case(spec, id));
    line["spec"] = spec.digest;
    file << line.dump() << "\n";
    output::flush_file(file, out);  // a shard that dies keeps the cases it finished
    ++done;
    if (progress && done % 10 == 0) std::fprintf(stderr, "sweep shard %d/%d: %d cases done\n", shard, shards, done);
  }
  output::finish_file(file, out);
  return done;
}

}  // namespace exc::sim
