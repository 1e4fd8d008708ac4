#include "harness/firmware_end.hpp"

#include <cstdio>

namespace exc::sim {

void HostFirmware::end_cycle() {
  node_->end_cycle();
  const app::FirmwareNode& n = *node_;
  status_.cycle = n.cycle();
  status_.mode = static_cast<std::uint8_t>(n.mode());
  status_.tracking = n.tracking();
  status_.task_time = n.task_time();
  for (int j = 0; j < 4; ++j) status_.q_desired[j] = n.q_desired()[j];
  for (int i = 0; i < 6; ++i) status_.theta_hat[i] = n.last_output().theta_hat[i];
  status_.safe_stops = n.supervisor().safe_stops();
  status_.fault_detected_time = n.supervisor().fault_detected_time();
  status_.last_fault = static_cast<std::uint16_t>(n.supervisor().last_fault());
}

app::RunSummaryRecord HostFirmware::finish() {
  node_->publish_counters();
  const app::FirmwareNode& n = *node_;
  app::RunSummaryRecord s;
  s.emergency_sent = n.supervisor().emergency_sent();
  s.tracking_samples = n.measured_tracking().samples();
  for (int j = 0; j < 4; ++j) {
    s.measured_rms[j] = n.measured_tracking().rms(j);
    s.measured_max[j] = n.measured_tracking().max_abs(j);
  }
  s.pump_limited_cycles = n.supervisor().pump_limited_cycles();
  s.trajectory_finished = n.trajectory_finished();
  s.finish_time = n.finish_time();
  s.mode = static_cast<std::uint8_t>(n.mode());
  std::snprintf(s.last_fault_text, sizeof s.last_fault_text, "%s", n.supervisor().last_fault_text());
  return s;
}

}  // namespace exc::sim
