#include "robustness.hpp"

#include <cmath>
#include <cstdio>

#include <stdexcept>

#include "report/run_report.hpp"

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

}  // namespace

std::vector<RobustnessRow> run_robustness(const SweepSpec& spec, const RunOptions& options) {
  check_controller_names(options.controllers);
  std::vector<RobustnessRow> rows;
  SweepSpec s = spec;
  s.duration = options.duration_override;
  const int total = s.total_cases();
  for (int id = 0; id < total; ++id) {
    const SweepCase c = sweep_case(s, id);
    const SceneBundle& bundle = s.sources[static_cast<std::size_t>(c.scene)]->nominal;
    RobustnessRow row;
    row.variant = std::to_string(id);
    if (c.variant >= 0) {
      row.variant = s.variants[static_cast<std::size_t>(c.variant)].name;
      row.description = s.variants[static_cast<std::size_t>(c.variant)].description;
    }
    if (options.progress)
      std::fprintf(stderr, "excavator-sim robustness: variant %d/%d %s (%s)\n", id + 1, total, row.variant.c_str(),
                   row.description.c_str());
    row.summary.scene = bundle.name;
    row.summary.setup = describe_setup(bundle);
    for (const std::string& name : options.controllers) {
      row.summary.runs.push_back(run_sweep_case(s, c, name));
      row.summary.all_ok = row.summary.all_ok && row.summary.runs.back().ok;
    }
    rows.push_back(row);
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
