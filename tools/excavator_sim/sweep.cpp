#include "sweep.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <stdexcept>

#include "settings/section_reader.hpp"
#include "control/controller_kinds.hpp"
#include "fault_campaign.hpp"
#include "harness/lockstep_run.hpp"

namespace exc::sim {
namespace {

namespace fs = std::filesystem;
using settings::Need;
using settings::SectionReader;

void read_range(SectionReader& p, const char* key, SweepRange& r, settings::Bounds bounds, const char* what) {
  if (!p.given(key)) return;
  std::array<double, 2> v{};
  p.numbers(key, v, bounds, "", what);
  if (v[1] < v[0]) p.fail(key, "max " + settings::format_number(v[1]) + " is below min " + settings::format_number(v[0]));
  r = SweepRange{true, v[0], v[1]};
}

double draw(std::mt19937_64& rng, const SweepRange& r, double fallback) {
  if (!r.given) return fallback;
  return r.min + (r.max - r.min) * std::uniform_real_distribution<double>(0.0, 1.0)(rng);
}

nlohmann::json per_joint(const double (&v)[4]) {
  return {{"swing", v[0]}, {"boom", v[1]}, {"arm", v[2]}, {"bucket", v[3]}};
}

}  // namespace

SweepSpec load_sweep_spec(const std::string& path) {
  const settings::Document doc = settings::Document::load(path);
  SectionReader top(doc);
  SectionReader s = top.section("sweep", "the sweep's mapping", Need::required);
  SweepSpec spec;
  spec.file = path;
  // One scene, or several: case i runs scene i mod their number.
  std::string scene;
  std::vector<std::string> scenes;
  s.text("scene", scene, "the scene file, relative to the spec", s.given("scenes") ? Need::optional : Need::required);
  s.texts("scenes", scenes, 1, "scene files relative to the spec, case i on scene i mod their number");
  if (!scene.empty() && !scenes.empty()) s.fail("scenes", "give scene or scenes, not both");
  if (scenes.empty()) scenes.push_back(scene);
  for (const std::string& f : scenes) spec.scene_paths.push_back(doc.resolve(f));
  spec.scene_path = spec.scene_paths.front();
  s.choices("controllers", spec.controllers, control::kControllerKinds, 1, "the controllers each case runs");
  s.whole("cases", spec.cases, 1, 1e6, "", "seeded random draws, case i from seed + i");
  s.whole("seed", spec.seed, 0, 4e9, "", "the draws' seed");
  if (s.given("duration")) s.number("duration", spec.duration, {1e-3, 3600}, "s", "per run (absent: the scene's)");
  SectionReader p = s.section("perturbations", "each drawn uniformly in [min, max] per case");
  read_range(p, "model_mass", spec.model_mass, {-0.9, 9}, "the firmware's link masses x (1 + value)");
  read_range(p, "soil_stiffness", spec.soil_stiffness, {0.01, 100}, "the plant's soil K x value");
  read_range(p, "position_noise", spec.position_noise, {0, 0.1}, "m (rad on the swing), 1 sigma");
  read_range(p, "delay_cycles", spec.delay_cycles, {0, 100}, "whole cycles, drawn as integers");
  p.finish();
  s.choices("faults", spec.faults, kFaultKinds, 0, "one fault per case, its kind drawn from the list");
  s.finish();
  top.finish();
  return spec;
}

SweepCase sweep_case(const SweepSpec& spec, int id) {
  // One generator per case, seeded from (seed, id): independent of which shard runs the case.
  std::seed_seq seq{spec.seed, static_cast<unsigned>(id), 0x5eedu};
  std::mt19937_64 rng(seq);
  SweepCase c;
  c.id = id;
  c.model_mass = draw(rng, spec.model_mass, 0);
  c.soil_stiffness = draw(rng, spec.soil_stiffness, 1);
  c.position_noise = draw(rng, spec.position_noise, 0);
  c.delay_cycles = static_cast<int>(std::floor(draw(rng, spec.delay_cycles, 0) + (spec.delay_cycles.given ? 0.5 : 0)));
  if (!spec.faults.empty()) draw_fault(rng, spec.faults, c);
  c.scene = id % static_cast<int>(spec.scene_paths.size());
  return c;
}

int run_sweep_shard(const SweepSpec& spec, int shard, int shards, const fs::path& out, bool progress) {
  std::vector<SceneBundle> nominal;
  for (const std::string& path : spec.scene_paths) {
    nominal.push_back(load_scene_bundle(path));
    check_faults_fit(spec.faults, nominal.back());
  }
  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());
  std::ofstream file(out);
  if (!file) throw std::runtime_error("cannot write " + out.string());
  int done = 0;
  for (int id = shard; id < spec.cases; id += shards) {
    const SweepCase c = sweep_case(spec, id);
    SceneBundle b = nominal[static_cast<std::size_t>(c.scene)];
    for (BodyInertia& body : b.firmware.machine.bodies) {
      body.mass *= 1 + c.model_mass;
      body.inertia *= 1 + c.model_mass;
    }
    b.scene.soil.stiffness *= c.soil_stiffness;
    b.scene.sensors.position_noise = Vec4::Constant(c.position_noise);
    b.scene.sensors.latency_cycles = c.delay_cycles;
    nlohmann::json line = {{"case", id},
                           {"model_mass", c.model_mass},
                           {"soil_stiffness", c.soil_stiffness},
                           {"position_noise", c.position_noise},
                           {"delay_cycles", c.delay_cycles}};
    if (nominal.size() > 1) line["scene"] = b.name;
    if (c.fault != "none")
      line["fault"] = {{"kind", c.fault}, {"start", c.fault_start}, {"duration", c.fault_duration},
                       {"joint", c.fault_joint}, {"magnitude", c.fault_magnitude}};
    for (const std::string& name : spec.controllers) {
      LockstepOptions o;
      o.controller = *control::kControllerKinds.named(name);
      o.duration = spec.duration;
      o.fault = fault_schedule(c, spec.seed);
      const RunRecord r = run_lockstep(b.scene, b.firmware, o);
      nlohmann::json run = {{"ok", r.ok}, {"rms_error", per_joint(r.rms_error)}, {"max_error", per_joint(r.max_error)}};
      if (!r.ok) run["failure"] = r.failure;
      run.update(run_outcome(r, b.firmware));  // the outcome the campaign counts, and its times
      line[name] = run;
    }
    file << line.dump() << "\n";
    file.flush();  // a shard that dies keeps the cases it finished
    ++done;
    if (progress && done % 10 == 0)
      std::fprintf(stderr, "sweep shard %d/%d: %d cases done\n", shard, shards, done);
  }
  return done;
}

bool merge_sweep(const SweepSpec& spec, const std::vector<fs::path>& shard_files, const fs::path& out_dir) {
  std::map<int, nlohmann::json> cases;
  for (const fs::path& f : shard_files) {
    std::ifstream in(f);
    if (!in) throw std::runtime_error("cannot read shard file " + f.string());
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      if (line.empty()) continue;
      nlohmann::json j;
      try {
        j = nlohmann::json::parse(line);
      } catch (const nlohmann::json::exception&) {
        // A shard killed mid-write leaves a torn last line: that case counts as missing.
        std::fprintf(stderr, "sweep merge: %s line %d: not a complete record, ignored\n", f.string().c_str(), n);
        continue;
      }
      cases[j["case"].get<int>()] = j;
    }
  }
  fs::create_directories(out_dir);
  std::ofstream csv(out_dir / "sweep.csv");
  csv << "case,model_mass,soil_stiffness,position_noise,delay_cycles";
  for (const std::string& c : spec.controllers)
    csv << ',' << c << "_ok," << c << "_rms_boom," << c << "_rms_arm," << c << "_rms_bucket";
  csv << "\n";
  csv.precision(17);
  std::vector<int> missing;
  std::map<std::string, std::map<std::string, int>> failures;  // controller -> region -> count
  nlohmann::json campaign = nlohmann::json::object();           // controller -> fault kind -> outcomes
  for (int id = 0; id < spec.cases; ++id) {
    const auto it = cases.find(id);
    if (it == cases.end()) {
      missing.push_back(id);
      continue;
    }
    const nlohmann::json& j = it->second;
    csv << id << ',' << j["model_mass"].get<double>() << ',' << j["soil_stiffness"].get<double>() << ','
        << j["position_noise"].get<double>() << ',' << j["delay_cycles"].get<int>();
    for (const std::string& c : spec.controllers) {
      const nlohmann::json& r = j[c];
      csv << ',' << (r["ok"].get<bool>() ? 1 : 0) << ',' << r["rms_error"]["boom"].get<double>() << ','
          << r["rms_error"]["arm"].get<double>() << ',' << r["rms_error"]["bucket"].get<double>();
      if (j.contains("fault")) count_campaign_run(campaign, j, c);
      if (!r["ok"].get<bool>()) {
        // The region of a failure: the perturbation that was largest relative to its range.
        const double stiff = j["soil_stiffness"].get<double>(), mass = std::abs(j["model_mass"].get<double>());
        const std::string region = stiff >= 2 ? "soil stiffness >= 2x" : mass >= 0.15 ? "model mass error >= 15 %"
                                   : j["delay_cycles"].get<int>() >= 2 ? "delay >= 2 cycles" : "elsewhere";
        ++failures[c][region];
      }
    }
    csv << "\n";
  }
  nlohmann::json summary = {{"spec", spec.file}, {"cases", spec.cases}, {"merged", cases.size()},
                            {"missing", missing}, {"failures", failures}, {"campaign", campaign}};
  std::ofstream(out_dir / "sweep.json") << summary.dump(2) << "\n";
  if (!missing.empty()) {
    std::fprintf(stderr, "sweep merge: %zu of %d cases missing (first: %d); rerun their shards\n", missing.size(),
                 spec.cases, missing.front());
    return false;
  }
  return true;
}

}  // namespace exc::sim
