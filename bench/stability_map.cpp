#include "stability_map.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

#include "bench_common.hpp"
#include "control/controller_registry.hpp"
#include "output_files/output_file.hpp"
#include "sweep/sweep.hpp"

namespace exc::bench {

namespace {

namespace fs = std::filesystem;
using sim::SweepCase;
using sim::SweepSpec;
using sim::SweepValue;

// The open loop as a sweep's run: the case's scene (its integrator, soil, ... as its knobs set them,
// read by the scene's readers) under the task's effort profile at the case's speed; with a search over
// the step, the first step (largest first) at which the plant's own checks pass.
json run_open_loop_case(const SweepSpec& spec, const SweepCase& c) {
  // A profile per scene, window and speed (computed once: the inverse dynamics along the task).
  static std::map<std::tuple<std::string, double, double, double>, EffortProfile> profiles;
  const std::size_t scene = static_cast<std::size_t>(c.scene);
  const BenchScene nominal = bench_scene(spec.sources[scene]->nominal, spec.window_start, spec.window_horizon);
  const double speed = c.value("profile.speed") ? c.value("profile.speed")->number : 1.0;
  const auto key = std::make_tuple(spec.scenes[scene], spec.window_start, spec.window_horizon, speed);
  auto p = profiles.find(key);
  if (p == profiles.end()) p = profiles.emplace(key, effort_profile(nominal, speed)).first;
  const auto run_with = [&](const sim::SweepSetting* searched) {
    const BenchScene s = bench_scene(sim::case_bundle(spec, c, searched), spec.window_start, spec.window_horizon);
    OpenLoopSettings st;
    st.integrator = s.scene.integrator;
    st.constraint_tolerance = 1e-4;  // the plant's default check
    return std::make_pair(run_open_loop(s, p->second, st), s.scene.integrator.step);
  };
  json run = {{"ok", false}, {"search_value", nullptr}};
  const std::size_t tries = spec.search.knob.empty() ? 1 : spec.search.values.size();
  for (std::size_t i = 0; i < tries; ++i) {
    const sim::SweepSetting searched{spec.search.knob, spec.search.knob.empty() ? SweepValue{} : spec.search.values[i]};
    const auto [r, step] = run_with(spec.search.knob.empty() ? nullptr : &searched);
    if (r.ok) {
      if (run.contains("failure")) run["failure_before"] = run["failure"];
      run.erase("failure");
      run["ok"] = true;
      run["search_value"] = step;
      break;
    }
    run["failure"] = r.failure;
  }
  json line = {{"case", c.id}, {"set", json::object()}, {"plant", run}};
  for (const sim::SweepSetting& v : c.set) line["set"][v.first] = v.second.to_json();
  return line;
}

// Runs a spec as one shard in this process and merges it into out/<name>/ (a merge that lost cases or
// a chart is added to `failed`); returns its case lines.
std::vector<json> run_spec(const SweepSpec& spec, const std::string& out, const sim::SweepRunner& runner,
                           std::vector<std::string>& failed) {
  const std::string name = fs::path(spec.file).stem().string();
  const fs::path dir = fs::path(out) / name;
  progress("stability %s: %s\n", name, std::to_string(spec.total_cases()) + " cases");
  sim::run_sweep_shard(spec, 0, 1, dir / "shard-0.jsonl", false, runner);
  if (!sim::merge_sweep(spec, {dir / "shard-0.jsonl"}, dir).ok()) failed.push_back(name);
  std::vector<json> lines;
  std::ifstream in(dir / "shard-0.jsonl");
  for (std::string line; std::getline(in, line);)
    if (!line.empty()) lines.push_back(json::parse(line));
  return lines;
}

// A spec of sweeps_dir with its scenes taken from scenes_dir (same file names).
SweepSpec load_spec(const std::string& sweeps_dir, const std::string& name, const std::string& scenes_dir) {
  return sim::load_sweep_spec(sweeps_dir + "/" + name, [&scenes_dir](std::vector<std::string> scenes) {
    for (std::string& s : scenes) s = (fs::path(scenes_dir) / fs::path(s).filename()).string();
    return scenes;
  });
}

// The CI cut: each axis named here keeps only these values.
void cut(SweepSpec& spec, const std::string& knob, const std::vector<double>& values) {
  for (sim::SweepGrid& g : spec.grids)
    for (sim::SweepAxis& a : g)
      if (a.knob == knob) {
        a.values.clear();
        for (double v : values) a.values.push_back(SweepValue{SweepValue::Type::number, v, {}, ""});
      }
  if (spec.search.knob == knob) {
    spec.search.values.clear();
    for (double v : values) spec.search.values.push_back(SweepValue{SweepValue::Type::number, v, {}, ""});
  }
}

std::vector<StepStability> step_rows(const std::vector<json>& lines, const std::string& knob, const char* axis) {
  std::vector<StepStability> rows;
  for (const json& j : lines) {
    StepStability r;
    r.method = j["set"]["integrator"].get<std::string>();
    r.axis = axis;
    r.value = j["set"][knob].get<double>();
    const json& p = j["plant"];
    if (p["ok"].get<bool>()) r.largest_stable_step = p["search_value"].get<double>();
    r.failure_above = p.value("failure_before", p.value("failure", ""));
    rows.push_back(r);
  }
  return rows;
}

double worst_rms(const json& run) {
  if (!run.contains("rms_error") || !run["rms_error"].is_object()) return NAN;  // never tracked: no figure
  double w = 0;
  for (const auto& [joint, v] : run["rms_error"].items()) w = std::max(w, v.is_number() ? v.get<double>() : NAN);
  return w;
}

}  // namespace

StabilityMaps stability_maps(const std::string& sweeps_dir, const std::string& scenes_dir, const std::string& out,
                             bool quick) {
  StabilityMaps maps;
  SweepSpec soil = load_spec(sweeps_dir, "stability_step_soil.yaml", scenes_dir);
  SweepSpec speed = load_spec(sweeps_dir, "stability_step_speed.yaml", scenes_dir);
  SweepSpec control = load_spec(sweeps_dir, "stability_control.yaml", scenes_dir);
  if (quick) {
    for (SweepSpec* s : {&soil, &speed}) {
      cut(*s, "integrator.step", {1e-2, 1e-3, 1e-4});
      s->window_horizon = 0.2;
    }
    soil.window_start = 3.0;
    cut(soil, "soil.stiffness", {2e4, 2e7});
    cut(speed, "profile.speed", {1, 3});
    control.duration = 1.0;
  }
  for (const auto& [spec, knob, axis] : {std::make_tuple(&soil, "soil.stiffness", "soil_stiffness_N_per_m"),
                                         std::make_tuple(&speed, "profile.speed", "joint_speed_factor")}) {
    const std::vector<StepStability> rows = step_rows(run_spec(*spec, out, run_open_loop_case, maps.failed_merges), knob, axis);
    maps.step.insert(maps.step.end(), rows.begin(), rows.end());
  }
  for (const json& j : run_spec(control, out, sim::run_closed_loop_case, maps.failed_merges)) {
    // The case's one set knob, copied out: a binding to `*items().begin()` refers into a temporary
    // that is gone by the next line (AddressSanitizer: stack-use-after-scope).
    const json::const_iterator set = j["set"].cbegin();
    const std::string knob = set.key();
    const json value = set.value();
    for (const std::string& c : control.controllers) {
      // A law that adapts nothing (PID) has no adaptation rate to scale.
      if (knob == "adaptation_scale" && control::controller_registry().at(c).adapts == control::Adapts::no) continue;
      ControlStability row;
      row.controller = c;
      row.axis = knob == "model_mass" ? "model_mass_error" : knob;
      row.value = value.get<double>();
      row.ok = j[c]["ok"].get<bool>();
      row.failure = j[c].value("failure", "");
      row.tracking = worst_rms(j[c]);
      maps.control.push_back(row);
    }
  }
  if (quick) return maps;
  for (const char* name : {"stability_valves.yaml", "stability_hydraulic_gains.yaml"}) {
    const SweepSpec spec = load_spec(sweeps_dir, name, scenes_dir);
    HydraulicMap m;
    m.name = fs::path(name).stem().string();
    m.dir = (fs::path(out) / m.name).string();
    std::map<std::string, std::map<std::string, int>> failures;  // "controller knob=value" -> kind -> runs
    for (const json& j : run_spec(spec, out, sim::run_closed_loop_case, maps.failed_merges))
      for (const std::string& c : spec.controllers) {
        ++m.runs;
        if (j[c]["ok"].get<bool>()) continue;
        ++m.failed;
        std::string where = c;
        for (const auto& [k, v] : j["set"].items()) where += " " + k.substr(k.rfind('.') + 1) + "=" + v.dump();
        const std::string f = j[c].value("failure", "");
        ++failures[where][f.rfind("plant stopped", 0) == 0 ? "plant" : "firmware"];
      }
    for (const auto& [where, kinds] : failures) {
      std::string line = where + ":";
      for (const auto& [kind, n] : kinds) line += " " + kind + " " + std::to_string(n);
      m.lines.push_back(line);
    }
    maps.hydraulic.push_back(m);
  }
  return maps;
}

void write_stability_csvs(const std::string& dir, const std::vector<StepStability>& steps,
                          const std::vector<ControlStability>& control) {
  std::ofstream f = output::open_file(dir + "/stability_step.csv");
  f << "method,axis,value,largest_stable_step_s,failure_at_next_larger_step\n";
  for (const StepStability& r : steps) {
    std::string failure = r.failure_above;
    std::replace(failure.begin(), failure.end(), ',', ';');
    f << r.method << ',' << r.axis << ',' << r.value << ',' << r.largest_stable_step << ",\"" << failure << "\"\n";
  }
  output::finish_file(f, dir + "/stability_step.csv");
  std::ofstream g = output::open_file(dir + "/stability_control.csv");
  g << "controller,axis,value,ok,tracking_rms_worst,failure\n";
  for (const ControlStability& r : control) {
    std::string failure = r.failure;
    std::replace(failure.begin(), failure.end(), ',', ';');
    g << r.controller << ',' << r.axis << ',' << r.value << ',' << r.ok << ',' << r.tracking << ",\"" << failure << "\"\n";
  }
  output::finish_file(g, dir + "/stability_control.csv");
}

}  // namespace exc::bench
