#include "in_process_run.hpp"

#include <cstdio>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "control/controller_registry.hpp"
#include "telemetry/lcm_output.hpp"

namespace exc::sim {

void check_controller_names(const std::vector<std::string>& names) {
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (!control::controller_registry().find(names[i]))
      throw std::invalid_argument("--controller: unknown controller '" + names[i] + "' (allowed: " +
                                  control::controller_registry().names() + ")");
    for (std::size_t k = 0; k < i; ++k)
      if (names[k] == names[i])
        throw std::invalid_argument("--controller: '" + names[i] + "' is given twice; each controller runs once");
  }
}

// The run's setup as a person reads it: actuators (and their lag), the firmware's compensation of it,
// the integrator.
std::string describe_setup(const SceneBundle& bundle) {
  const plant::Scene& sc = bundle.scene;
  std::ostringstream o;
  o << "actuators " << sc.actuators.fidelity;
  if (const auto lag = plant::fidelity_of(sc.actuators).effort_lag) o << " (effort lag " << lag(sc.actuators) * 1e3 << " ms)";
  const control::ControllerConfig& c = bundle.firmware.controller;
  if (c.command_interface == control::CommandInterface::valve) {
    o << ", firmware commands the valves (pilot pressures; force loop T_f " << c.actuation.valves.force_time_constant * 1e3
      << " ms, spool lead to " << c.actuation.valves.spool_lag_target * 1e3 << " ms)";
  } else {
    o << ", firmware commands efforts, lag compensation ";
    if (c.actuation.actuator_lag > 0)
      o << c.actuation.actuator_lag * 1e3 << " ms -> " << c.actuation.actuator_lag_target * 1e3 << " ms";
    else
      o << "off";
  }
  const app::FirmwareSettings& fw = bundle.firmware;
  if (fw.task.timing_scale != 1) {
    o << "; task timing scaled by " << fw.task.timing_scale << " to fit the actuators' limits";
    if (fw.duration != fw.scene_duration)
      o << ", the run's duration with it (" << fw.scene_duration << " s -> " << fw.duration << " s)";
    else
      o << " (the run's " << fw.duration << " s cover part of the path, as the scene asks)";
  }
  o << "; integrator " << sc.integrator.method << " / " << plant::to_string(sc.integrator.formulation)
    << " at " << sc.integrator.step * 1e3 << " ms";
  return o.str();
}

Summary run_all(const SceneBundle& bundle, const RunOptions& options) {
  check_controller_names(options.controllers);  // all of them, before the first run
  Summary summary;
  summary.scene = bundle.name;
  summary.setup = describe_setup(bundle);
  std::shared_ptr<telemetry::LcmOutput> output;
  if (!options.lcm_url.empty()) {
    std::string error;
    output = telemetry::LcmOutput::open(options.lcm_url, &error);
    if (!output) throw std::runtime_error("--lcm: " + error);
  }
  for (const std::string& name : options.controllers) {
    if (options.progress) std::fprintf(stderr, "excavator-sim: %s with %s\n", bundle.name.c_str(), name.c_str());
    LockstepOptions lo;
    lo.controller = name;
    lo.duration = options.duration_override;
    lo.telemetry = output;
    lo.log_every = options.log_every;
    lo.progress = options.progress;
    lo.firmware_target = options.firmware_target;
    lo.interrupt = options.interrupt;
    summary.runs.push_back(run_lockstep(bundle.scene, bundle.firmware, lo));
    summary.all_ok = summary.all_ok && summary.runs.back().ok;
    if (summary.runs.back().interrupted) {
      summary.interrupted = true;
      break;
    }
  }
  return summary;
}

}  // namespace exc::sim
