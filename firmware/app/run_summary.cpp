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

nlohmann::json timing_json(const diagnostics::PerfCounter& c) {
  if (c.count() == 0) return nullptr;
  return {{"median", c.median_us()}, {"p99", c.p99_us()}, {"p99_9", c.percentile_us(0.999)}, {"max", c.max_us()},
          {"count", c.count()}};
}

nlohmann::json per_joint(const double (&v)[4]) {
  nlohmann::json j;
  for (int i = 0; i < 4; ++i) j[kActiveNames[i]] = v[i];
  return j;
}

// One console line of a phase's worst errors (nothing for a phase the run was never in).
void print_phase(std::FILE* out, const char* what, const PhaseErrors& p) {
  if (p.samples == 0) return;
  std::fprintf(out,
               "excavator-firmware: %s, %.1f s: max error swing %.2f mrad, boom %.2f, arm %.2f, bucket %.2f mm "
               "(RMS %.2f / %.2f / %.2f mm); past the holding tolerance %llu / %llu / %llu time(s)\n",
               what, p.seconds, p.max_error[0] * 1e3, p.max_error[1] * 1e3, p.max_error[2] * 1e3, p.max_error[3] * 1e3,
               p.rms_error[1] * 1e3, p.rms_error[2] * 1e3, p.rms_error[3] * 1e3,
               static_cast<unsigned long long>(p.excursions[1]), static_cast<unsigned long long>(p.excursions[2]),
               static_cast<unsigned long long>(p.excursions[3]));
}

std::uint64_t telemetry_dropped(const RunContext& run) {
  return run.publisher ? run.publisher->counters().dropped_full_total : 0;
}

}  // namespace

nlohmann::json phase_json(const PhaseErrors& p) {
  if (p.samples == 0) return nullptr;
  nlohmann::json excursions;
  for (int i = 0; i < 4; ++i) excursions[kActiveNames[i]] = p.excursions[i];
  return {{"seconds", p.seconds}, {"samples", p.samples}, {"rms_error", per_joint(p.rms_error)},
          {"max_error", per_joint(p.max_error)}, {"worst_time", per_joint(p.worst_time)},
          {"excursions", excursions}};
}

nlohmann::json phases_json(const PhaseErrors& tracking, const PhaseErrors& settle, const PhaseErrors& hold,
                           const PhaseErrors& stop) {
  return {{"tracking", phase_json(tracking)}, {"settle", phase_json(settle)}, {"hold", phase_json(hold)},
          {"stop", phase_json(stop)}};
}

nlohmann::json holding_tolerance_json() { return per_joint(kHoldingTolerance); }

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
  // The errors per phase, on the sensed positions against the pose asked for.
  const RunnerOutcome& o = run.outcome;
  print_phase(out, "tracking (the path running)", o.tracking);
  char what[200];
  std::snprintf(what, sizeof what,
                "settle (a hold's start, until every function stayed inside half the tolerance for %.1f s, at most %.0f s)",
                kHoldSettleDwell, kHoldSettleLimit);
  print_phase(out, what, o.settle);
  if (o.hold.samples > 0) {
    const std::string held = hold_failure(o.hold);
    std::snprintf(what, sizeof what, "hold (once settled; holding tolerance %.1f mm, %.1f mrad swing: %s)",
                  kHoldingTolerance[1] * 1e3, kHoldingTolerance[0] * 1e3, held.empty() ? "met" : "NOT met");
    print_phase(out, what, o.hold);
  }
  print_phase(out, "stop (the safe state: valves centred)", o.stop);
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
  // Every phase (the tracking figures above are the first), on the sensed positions; the verdict
  // holds the hold to the holding tolerance ("hold_ok").
  j["phases"] = phases_json(run.outcome.tracking, run.outcome.settle, run.outcome.hold, run.outcome.stop);
  j["holding_tolerance"] = holding_tolerance_json();
  j["hold_settle_limit_seconds"] = kHoldSettleLimit;
  j["hold_ok"] = hold_failure(run.outcome.hold).empty();
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
