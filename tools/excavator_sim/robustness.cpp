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

// PID's RMS error over the adaptive law's, arm and bucket; false unless both ran.
bool pid_over_adaptive(const Summary& s, double& arm, double& bucket) {
  const RunResult* pid = find(s, "pid");
  const RunResult* ad = find(s, "adaptive");
  if (!pid || !ad) return false;
  arm = pid->rms_error[2] / ad->rms_error[2];
  bucket = pid->rms_error[3] / ad->rms_error[3];
  return true;
}

// The single faults; the "all" variant applies every one of them (mass +20 %).
// The firmware's model has every link's mass and inertia scaled while the plant keeps the true machine.
void scale_model_masses(SceneBundle& b, double scale) {
  for (BodyInertia& body : b.firmware.machine.bodies) {
    body.mass *= scale;
    body.inertia *= scale;
  }
}
void heavier_model(SceneBundle& b, RunOptions&) { scale_model_masses(b, 1.2); }
void lighter_model(SceneBundle& b, RunOptions&) { scale_model_masses(b, 0.8); }
// Noise of the order of a good encoder chain: 0.1 mm on a stroke, 0.2 mrad on the swing, and a
// velocity signal (differentiated in the drive) ten times noisier than a clean one.
void sensor_noise(SceneBundle& b, RunOptions&) {
  b.scene.sensors.position_noise = Vec4(2e-4, 1e-4, 1e-4, 1e-4);
  b.scene.sensors.velocity_noise = Vec4(5e-3, 5e-3, 5e-3, 5e-3);
}
void sensor_delay(SceneBundle& b, RunOptions&) { b.scene.sensors.latency_cycles = 2; }
void stiffer_soil(SceneBundle& b, RunOptions&) { b.scene.soil.stiffness *= 3.0; }

}  // namespace

std::vector<RobustnessVariant> standard_robustness_variants() {
  return {
      {"nominal", "exact model, the scene's sensors and soil", [](SceneBundle&, RunOptions&) {}},
      {"mass-20%", "controller's model: every link 20 % lighter than the plant", lighter_model},
      {"mass+20%", "controller's model: every link 20 % heavier than the plant", heavier_model},
      {"noise", "sensor noise: position 0.2 mrad / 0.1 mm, velocity 5 mrad/s / 5 mm/s (1 sigma)", sensor_noise},
      {"delay2", "sensor frames 2 cycles late (2 ms)", sensor_delay},
      {"soil-K x3", "plant's soil 3x stiffer than the controller's initial estimate", stiffer_soil},
      {"all", "mass+20%, noise, 2-cycle delay and 3x stiffer soil at once",
       [](SceneBundle& b, RunOptions& o) {
         for (auto* fault : {heavier_model, sensor_noise, sensor_delay, stiffer_soil}) fault(b, o);
       }},
  };
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
    double arm = 0, bucket = 0;
    if (pid_over_adaptive(row.summary, arm, bucket)) {
      std::snprintf(line, sizeof line, "%-10s %-10s %8s %8s %7.1fx %7.1fx\n", "", "PID/adapt.", "", "", arm, bucket);
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
    double arm = 0, bucket = 0;
    if (pid_over_adaptive(row.summary, arm, bucket)) v["pid_over_adaptive_rms"] = {{"arm", arm}, {"bucket", bucket}};
    j.push_back(v);
  }
  return {{"robustness", j}};
}

}  // namespace exc::sim
