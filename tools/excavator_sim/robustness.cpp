#include "robustness.hpp"

#include <cmath>
#include <cstdio>

#include "run_report.hpp"

namespace exc::sim {
namespace {

const RunResult* find(const Summary& s, const std::string& controller) {
  for (const RunResult& r : s.runs)
    if (r.controller == controller) return &r;
  return nullptr;
}

}  // namespace

std::vector<RobustnessVariant> standard_robustness_variants() {
  std::vector<RobustnessVariant> v;
  v.push_back({"nominal", "exact model, the scene's sensors and soil", [](SceneBundle&, RunOptions&) {}});
  v.push_back({"mass-20%", "controller's model: every link 20 % lighter than the plant",
               [](SceneBundle&, RunOptions& o) { o.controller_mass_scale = 0.8; }});
  v.push_back({"mass+20%", "controller's model: every link 20 % heavier than the plant",
               [](SceneBundle&, RunOptions& o) { o.controller_mass_scale = 1.2; }});
  // Noise of the order of a good encoder chain: 0.1 mm on a stroke, 0.2 mrad on the swing, and a
  // velocity signal (differentiated in the drive) ten times noisier than a clean one.
  v.push_back({"noise", "sensor noise: position 0.2 mrad / 0.1 mm, velocity 5 mrad/s / 5 mm/s (1 sigma)",
               [](SceneBundle& b, RunOptions&) {
                 b.scene.sensors.position_noise = Vec4(2e-4, 1e-4, 1e-4, 1e-4);
                 b.scene.sensors.velocity_noise = Vec4(5e-3, 5e-3, 5e-3, 5e-3);
               }});
  v.push_back({"delay2", "sensor frames 2 cycles late (2 ms)",
               [](SceneBundle& b, RunOptions&) { b.scene.sensors.latency_cycles = 2; }});
  v.push_back({"soil-K x3", "plant's soil 3x stiffer than the controller's initial estimate",
               [](SceneBundle& b, RunOptions&) { b.scene.soil.stiffness *= 3.0; }});
  v.push_back({"all", "mass+20%, noise, 2-cycle delay and 3x stiffer soil at once",
               [](SceneBundle& b, RunOptions& o) {
                 o.controller_mass_scale = 1.2;
                 b.scene.sensors.position_noise = Vec4(2e-4, 1e-4, 1e-4, 1e-4);
                 b.scene.sensors.velocity_noise = Vec4(5e-3, 5e-3, 5e-3, 5e-3);
                 b.scene.sensors.latency_cycles = 2;
                 b.scene.soil.stiffness *= 3.0;
               }});
  return v;
}

std::vector<RobustnessRow> run_robustness(const SceneBundle& nominal, const RunOptions& options,
                                          const std::vector<RobustnessVariant>& variants) {
  std::vector<RobustnessRow> rows;
  for (std::size_t i = 0; i < variants.size(); ++i) {
    SceneBundle bundle = nominal;
    RunOptions o = options;
    o.lcm_url.clear();  // no telemetry: the figures are in the summary
    variants[i].apply(bundle, o);
    if (options.progress)
      std::fprintf(stderr, "excavator-sim robustness: variant %zu/%zu %s (%s)\n", i + 1, variants.size(),
                   variants[i].name.c_str(), variants[i].description.c_str());
    rows.push_back({variants[i].name, variants[i].description, run_all(bundle, o)});
  }
  return rows;
}

void print_robustness(const std::vector<RobustnessRow>& rows, std::ostream& out) {
  char line[256];
  out << "\nRMS tracking error (mm; swing in mrad) per variant and controller\n";
  std::snprintf(line, sizeof line, "%-10s %-10s %8s %8s %8s %8s   %s\n", "variant", "controller", "swing", "boom",
                "arm", "bucket", "status");
  out << line;
  for (const RobustnessRow& row : rows) {
    for (const RunResult& r : row.summary.runs) {
      std::snprintf(line, sizeof line, "%-10s %-10s %8.3f %8.3f %8.3f %8.3f   %s\n", row.variant.c_str(),
                    r.controller.c_str(), 1e3 * r.rms_error[0], 1e3 * r.rms_error[1], 1e3 * r.rms_error[2],
                    1e3 * r.rms_error[3], r.ok ? "ok" : r.failure.c_str());
      out << line;
    }
    const RunResult* pid = find(row.summary, "pid");
    const RunResult* ad = find(row.summary, "adaptive");
    if (pid && ad) {
      std::snprintf(line, sizeof line, "%-10s %-10s %8s %8s %7.1fx %7.1fx\n", "", "PID/adapt.", "", "",
                    pid->rms_error[2] / ad->rms_error[2], pid->rms_error[3] / ad->rms_error[3]);
      out << line;
    }
  }
  out << "\nvariants:\n";
  for (const RobustnessRow& row : rows) out << "  " << row.variant << ": " << row.description << "\n";
}

nlohmann::json robustness_json(const std::vector<RobustnessRow>& rows) {
  nlohmann::json j = nlohmann::json::array();
  for (const RobustnessRow& row : rows) {
    nlohmann::json v = to_json(row.summary);
    v["variant"] = row.variant;
    v["description"] = row.description;
    const RunResult* pid = find(row.summary, "pid");
    const RunResult* ad = find(row.summary, "adaptive");
    if (pid && ad)
      v["pid_over_adaptive_rms"] = {{"arm", pid->rms_error[2] / ad->rms_error[2]},
                                    {"bucket", pid->rms_error[3] / ad->rms_error[3]}};
    j.push_back(v);
  }
  return {{"robustness", j}};
}

}  // namespace exc::sim
