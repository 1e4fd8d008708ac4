#pragma once
// What excavator-firmware says about a run when it ends: one console line and the JSON summary
// (--json): verdict, the errors per phase (tracking, settle, hold, stop) with the hold's verdict
// against the holding tolerance, loop timing, deadlines, faults, CAN and telemetry counters. The
// phases' JSON is excavator-sim's too (report/run_report.cpp).
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/firmware_node.hpp"
#include "app/firmware_runner.hpp"
#include "app/run_phases.hpp"
#include "telemetry/telemetry_publisher.hpp"

namespace exc::app {

struct RunContext {
  const FirmwareNode& node;
  const RunnerOutcome& outcome;
  const char* controller = "";  // the law's name
  bool realtime = false;
  double period_s = 0;
  std::uint64_t can_frames_rejected = 0;
  const telemetry::TelemetryPublisher* publisher = nullptr;  // null: the run published no telemetry
  telemetry::OverflowPolicy overflow = telemetry::OverflowPolicy::block;
};

// One phase's figures: seconds, samples, RMS and max error, the max's time and the excursions past
// the holding tolerance, per joint (null when the run never was in it).
nlohmann::json phase_json(const PhaseErrors& phase);
// {"tracking", "settle", "hold", "stop"}: each phase_json.
nlohmann::json phases_json(const PhaseErrors& tracking, const PhaseErrors& settle, const PhaseErrors& hold,
                           const PhaseErrors& stop);
// The holding tolerance per joint (rad swing, m cylinders).
nlohmann::json holding_tolerance_json();

// The console's closing lines: counts and timing, the errors per phase, then "ok" or "FAILED: why".: counts and timing, then "ok" or "FAILED: why".
void print_run_summary(const RunContext& run, std::FILE* out);
nlohmann::json run_summary_json(const RunContext& run);

}  // namespace exc::app
