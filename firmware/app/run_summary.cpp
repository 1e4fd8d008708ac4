#include "app/run_summary.hpp"

#include "app/float_environment.hpp"
#include "model/types.hpp"

namespace exc::app {

namespace {

// Per joint; null when the firmware never tracked (a metric of no samples is not 0).
nlohmann::json per_joint(const TrackingMetrics& m, bool rms) {
  if (m.samples() == 0) return nullptr;
  nlohmann::json j;
  for (int i = 0; i < 4; ++i) j[kActiveNames[i]] = rms ? m.rms(i) : m.max_abs(i);
  return j;
}

nlohmann::json timing_json(const control::PerfCounter& c) {
  if (c.count() == 0) return nullptr;
  return {{"median", c.median_us()}, {"p99", c.p99_us()}, {"p99_9", c.percentile_us(0.999)}, {"max", c.max_us()},
          {"count", c.count()}};
}

std::uint64_t telemetry_dropped(const RunContext& run) {
  return run.publisher ? run.publisher->counters().dropped_full_total : 0;
}

}  // namespace

void print_run_summary(const RunContext& run, std::FILE* out) {
  const auto& c = run.node.control_timing();
  std::fprintf(out,
               "excavator-firmware: %llu cycles of %.3g ms; control step median %.1f us, p99 %.1f us, max %.1f us; "
               "deadline overruns %llu, skipped periods %llu; safe stops %llu; CAN rejects %llu; telemetry dropped %llu\n",
               static_cast<unsigned long long>(run.outcome.cycles), run.period_s * 1e3, c.median_us(), c.p99_us(),
               c.max_us(), static_cast<unsigned long long>(run.outcome.overruns),
               static_cast<unsigned long long>(run.outcome.skipped_periods),
               static_cast<unsigned long long>(run.node.supervisor().safe_stops()),
               static_cast<unsigned long long>(run.can_frames_rejected),
               static_cast<unsigned long long>(telemetry_dropped(run)));
  std::fprintf(out, "excavator-firmware: %s%s\n", run.outcome.ok ? "ok" : "FAILED: ", run.outcome.failure.c_str());
}

nlohmann::json run_summary_json(const RunContext& run) {
  const FirmwareNode& node = run.node;
  nlohmann::json j;
  j["ok"] = run.outcome.ok;
  if (!run.outcome.ok) j["failure"] = run.outcome.failure;
  j["controller"] = run.controller;
  j["mode"] = run.realtime ? "realtime" : "lockstep";
  j["float_mode"] = kFloatModes.name_of(float_mode_of_thread());  // the loop thread's, at its end
  j["period_s"] = run.period_s;
  j["cycles"] = run.outcome.cycles;
  j["tracking"] = {{"rms_error", per_joint(node.measured_tracking(), true)},
                   {"max_error", per_joint(node.measured_tracking(), false)}};
  j["tracking_samples"] = node.measured_tracking().samples();
  j["control_step_us"] = timing_json(node.control_timing());
  j["cycle_us"] = timing_json(node.cycle_timing());
  j["deadlines"] = {{"overruns", run.outcome.overruns}, {"skipped_periods", run.outcome.skipped_periods},
                    {"interval_us", timing_json(node.interval_timing())}};
  j["safe_stops"] = node.supervisor().safe_stops();
  j["estop"] = node.supervisor().emergency_sent();  // any FW_EMERGENCY with EmergencyStop = 1, the last command included
  if (node.supervisor().safe_stops() > 0) j["last_fault"] = node.supervisor().last_fault_text();
  j["task_finished"] = node.trajectory_finished();
  j["can_frames_rejected"] = run.can_frames_rejected;
  if (run.publisher) {
    const telemetry::TelemetryCounters tcn = run.publisher->counters();
    nlohmann::json dropped;
    for (std::size_t i = 0; i < telemetry::channel_count; ++i)
      dropped[run.publisher->channel_name(static_cast<telemetry::Channel>(i))] = tcn.dropped_full[i];
    j["telemetry"] = {{"enqueued", tcn.enqueued}, {"published", tcn.published}, {"dropped", tcn.dropped_full_total},
                      {"dropped_by_channel", dropped}, {"ring_high_water", tcn.ring_high_water},
                      {"ring_capacity", tcn.ring_capacity}, {"overflow_policy", telemetry::to_string(run.overflow)}};
  }
  return j;
}

}  // namespace exc::app
