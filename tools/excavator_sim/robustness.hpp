#pragma once
// Robustness of the controllers on one scene: the same run with the controller's model, the sensors
// or the soil made wrong on purpose (issue 5: +-20 % model mass, sensor noise and delay, a soil three
// times stiffer than the controller's nominal estimate), PID against adaptive in each.
#include <functional>
#include <ostream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "in_process_run.hpp"

namespace exc::sim {

struct RobustnessVariant {
  std::string name;         // short key, e.g. "mass+20%"
  std::string description;  // what is wrong, in words
  // Makes this variant's scene and options from the nominal ones.
  std::function<void(SceneBundle&, RunOptions&)> apply;
};

// The shipped set, in the order they are run: nominal first (the reference for the others).
std::vector<RobustnessVariant> standard_robustness_variants();

struct RobustnessRow {
  std::string variant, description;
  Summary summary;  // one run per controller
};

std::vector<RobustnessRow> run_robustness(const SceneBundle& nominal, const RunOptions& options,
                                          const std::vector<RobustnessVariant>& variants);

// Table: per variant and controller, RMS error of each joint, and the PID / adaptive ratio of arm and
// bucket when both ran.
void print_robustness(const std::vector<RobustnessRow>& rows, std::ostream& out);
nlohmann::json robustness_json(const std::vector<RobustnessRow>& rows);

}  // namespace exc::sim
