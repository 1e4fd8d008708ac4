#pragma once
// The stability maps: the largest stable step of every integrator against soil stiffness and joint
// speed, and each controller's stability against gains, adaptation, noise, delay and mass error.
#include <string>
#include <vector>

#include "bench_runs.hpp"

namespace exc::bench {

struct StepStability {
  std::string method, axis;
  double value = 0, largest_stable_step = NAN;
  std::string failure_above;  // what the plant's checks said at the next larger step
};

struct ControlStability {
  std::string controller, axis;
  double value = 0;
  bool ok = false;
  double tracking = NAN;
  std::string failure;
};

std::vector<StepStability> step_stability_map(const BenchScene& dig, const BenchScene& free,
                                              const std::vector<double>& steps, const std::vector<double>& stiffness,
                                              const std::vector<double>& speeds);
std::vector<ControlStability> control_stability_map(const BenchScene& dig, double duration);
void write_stability_csvs(const std::string& dir, const std::vector<StepStability>& steps,
                          const std::vector<ControlStability>& control);

}  // namespace exc::bench
