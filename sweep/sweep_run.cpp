// A sweep's runs: a case's scene and settings made from its draws and set values, each controller
// through run_lockstep, one JSON line per case into the shard's file.
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "fault_campaign.hpp"
#include "output_files/output_file.hpp"
#include "report/run_report.hpp"
#include "sweep.hpp"

namespace exc::sim {
namespace {

namespace fs = std::filesystem;

RunRecord run_bundle(const SceneBundle& b, const SweepSpec& spec, const SweepCase& c, const std::string& controller) {
  LockstepOptions o;
  o.controller = controller;
  o.duration = spec.duration;
  o.stop_at_safe_state = spec.stop_at_safe_state;
  o.fault = fault_schedule(c, spec.seed);
  // A faulted run that stopped is judged by the machine coming to rest: it runs on past the scene's
  // end for up to kCampaignRestHorizon after the stop, so a late rest is measured, not cut off.
  if (o.fault.kind != FaultSchedule::Kind::none) o.rest_horizon = kCampaignRestHorizon;
  return run_lockstep(b.scene, b.firmware, o);
}

}  // namespace

RunRecord run_sweep_case(const SweepSpec& spec, const SweepCase& c, const std::string& controller) {
  return run_bundle(case_bundle(spec, c), spec, c, controller);
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
  nlohmann::json line = {{"case", c.id}};
  for (std::size_t i = 0; i < c.drawn.size(); ++i) {
    const double x = c.drawn[i].second.number;
    line[c.drawn[i].first] = spec.perturbations[i].whole ? nlohmann::json(std::llround(x)) : nlohmann::json(x);
  }
  if (spec.scenes.size() > 1) line["scene"] = spec.sources[static_cast<std::size_t>(c.scene)]->nominal.name;
  if (c.variant >= 0) line["variant"] = spec.variants[static_cast<std::size_t>(c.variant)].name;
  if (!c.set.empty()) {
    line["set"] = nlohmann::json::object();
    for (const SweepSetting& s : c.set) line["set"][s.first] = s.second.to_json();
  }
  if (c.fault != "none")
    line["fault"] = {{"kind", c.fault}, {"start", c.fault_start}, {"duration", c.fault_duration},
                     {"joint", c.fault_joint}, {"magnitude", c.fault_magnitude}};
  // The case's scene read once (once per searched value) for all its controllers.
  const SceneBundle bundle = spec.search.knob.empty() ? case_bundle(spec, c) : SceneBundle{};
  for (const std::string& name : spec.controllers) {
    if (spec.search.knob.empty()) {
      line[name] = record_json(run_bundle(bundle, spec, c, name), bundle.firmware);
      continue;
    }
    // The search: the first value (in the spec's order) whose run passes; the failure of the one before.
    nlohmann::json run = {{"ok", false}, {"search_value", nullptr}};
    for (const SweepValue& v : spec.search.values) {
      const SweepSetting s{spec.search.knob, v};
      const SceneBundle searched = case_bundle(spec, c, &s);
      const RunRecord r = run_bundle(searched, spec, c, name);
      if (r.ok) {
        const std::string before = run.value("failure", "");
        run = record_json(r, searched.firmware);
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

namespace {

// "1 min 05 s", "42 s".
std::string duration_text(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char text[48];
  if (s >= 3600)
    std::snprintf(text, sizeof text, "%ld h %02ld min", s / 3600, s / 60 % 60);
  else if (s >= 60)
    std::snprintf(text, sizeof text, "%ld min %02ld s", s / 60, s % 60);
  else
    std::snprintf(text, sizeof text, "%ld s", s);
  return text;
}

}  // namespace

std::string sweep_progress_text(int shard, int shards, int done, int count, double elapsed_s) {
  std::string text = "sweep";
  if (shards > 1) text += " shard " + std::to_string(shard) + "/" + std::to_string(shards);
  text += ": " + std::to_string(done) + " of " + std::to_string(count) + " cases, " + duration_text(elapsed_s) + " elapsed";
  if (done > 0 && done < count)
    text += ", ~" + duration_text(elapsed_s / done * (count - done)) + " left";
  return text;
}

int run_sweep_shard(const SweepSpec& spec, int shard, int shards, const fs::path& out, bool progress,
                    const SweepRunner& runner) {
  if (!out.parent_path().empty()) fs::create_directories(out.parent_path());
  std::ofstream file = output::open_file(out);
  // A fault the scenes cannot take (pump_loss without the hydraulic machine) before any run.
  if (!spec.faults.empty())
    for (const std::shared_ptr<const SceneSource>& scene : spec.sources) check_faults_fit(spec.faults, scene->nominal);
  int done = 0;
  const int total = spec.total_cases();
  const int count = shard < total ? (total - shard + shards - 1) / shards : 0;  // this shard's cases
  // The progress line is for a person at a terminal, redrawn in place; a log or a pipe gets none.
  const bool show = progress && ::isatty(STDERR_FILENO) == 1;
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  Clock::time_point shown = start;
  for (int id = shard; id < total; id += shards) {
    nlohmann::json line = runner(spec, sweep_case(spec, id));
    line["spec"] = spec.digest;
    file << line.dump() << "\n";
    output::flush_file(file, out);  // a shard that dies keeps the cases it finished
    ++done;
    const Clock::time_point now = Clock::now();
    if (show && (done == count || now - shown >= std::chrono::milliseconds(250))) {
      shown = now;
      const std::string text = sweep_progress_text(shard, shards, done, count, std::chrono::duration<double>(now - start).count());
      std::fprintf(stderr, "\r%s\033[K%s", text.c_str(), done == count ? "\n" : "");
      std::fflush(stderr);
    }
  }
  output::finish_file(file, out);
  return done;
}

}  // namespace exc::sim
