#pragma once
// Robustness of the controllers on one scene: the same run with the controller's model, the sensors
// or the soil made wrong on purpose (+-20 % model mass, sensor noise and delay, a soil three
// times stiffer than the controller's nominal estimate), PID against adaptive in each. The variants
// are a sweep spec's (sweeps/robustness.yaml), run through the sweep's cases.
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "report/in_process_run.hpp"
#include "sweep.hpp"

namespace exc::sim {

struct RobustnessRow {
  std::string variant, description;
  Summary summary;  // one run per controller
};

// Runs a sweep spec's cases (sweeps/robustness.yaml: one variant each) in this process, each with
// options.controllers on the spec's scenes, keeping every run's whole record.
std::vector<RobustnessRow> run_robustness(const SweepSpec& spec, const RunOptions& options);

// Table: per variant and controller, RMS error of each joint, and the PID / adaptive ratio of arm and
// bucket when both ran.
void print_robustness(const std::vector<RobustnessRow>& rows, std::ostream& out);
nlohmann::json robustness_json(const std::vector<RobustnessRow>& rows);

}  // namespace exc::sim
