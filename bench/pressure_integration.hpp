#pragma once
// The pressure-integration chart: how the hydraulic machine's chamber pressures are
// integrated, as error against CPU time. The machine is driven open loop by valve commands held over
// kProfileHold each, so every substep (up to the hold) and pressure method integrates the same input
// from the same state. Two inputs: the commands a closed-loop dig sent (the firmware's pilot
// pressures, recorded once), and all four functions driven through their valves' range by a fixed
// profile (overrunning loads, reliefs, pump saturation, end stops). Per input, method
// (integrator.pressure_method: backward or forward Euler per chamber) and substep: CPU time per
// simulated second, the RMS distance of the tip path and of the eight chamber pressures from a fine
// reference (backward Euler at 10 us), the chamber solves' iterations, and for a run the plant's own
// checks stopped, their message. The explicit method's largest passing substep is found between the
// listed ones.
#include <string>
#include <vector>

#include "bench_runs.hpp"
#include "sim_plant/actuators.hpp"

namespace exc::bench {

// A driven open-loop input: the scene (plant side) and one command per kProfileHold from its start.
struct ValveInput {
  std::string name;
  plant::Scene scene;
  std::vector<plant::ActuatorCommand> commands;
};

// The commands the plant received in the first `duration` seconds of a closed-loop run of the
// (hydraulic) scene, the one in the middle of each hold.
ValveInput recorded_dig(const BenchScene& dig, double duration);
// The four-function profile of the energy test (tests/plant/test_hydraulics.cpp): valve openings
// 0.6 sin 2t, 0.8 sin(1.3t + 0.5), -0.7 sin 1.7t, 0.9 sin(2.3t + 1) from the reference pose, in the
// air (tests/plant/test_pressure_method.cpp runs it too).
ValveInput four_functions(const BenchScene& dig, double duration);

struct PressurePoint {
  std::string input, method;  // method: a kPressureMethods name
  double step = 0;            // s
  bool ok = false;
  std::string failure;        // the plant's check that stopped the run
  double failed_at = 0;       // s
  double cpu_per_s = 0;       // thread CPU seconds per simulated second
  double tip_rms = 0;         // m, against the reference
  double pressure_rms = 0;    // Pa, the eight chambers against the reference
  double iterations = 0;      // chamber-solve iterations per substep (eight solves), mean
  double cavitation = 0;      // s the plant counted a chamber at the vapour floor
};

// Where forward Euler stops on one input: the largest substep it passed below the smallest it
// failed at (0: none).
struct ExplicitBoundary {
  std::string input;
  double stable = 0, failing = 0;
  std::string failure;
};

struct PressureChart {
  std::vector<PressurePoint> points;
  std::vector<ExplicitBoundary> boundaries;
  double reference_step = 0;
};

// steps: substeps that divide kProfileHold (those above 1 ms are also the plant's cycle).
PressureChart pressure_integration(const std::vector<ValveInput>& inputs, const std::vector<double>& steps,
                                   double reference_step);
void write_pressure_csv(const std::string& path, const PressureChart& chart);

}  // namespace exc::bench
