#pragma once
// What excavator-firmware says about a run when it ends: one console line and the JSON summary
// (--json): verdict, tracking figures, loop timing, deadlines, faults, CAN and telemetry counters.
#include <cstdio>
#include <nlohmann/json.hpp>

#include "app/firmware_node.hpp"
#include "app/firmware_runner.hpp"
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

// The console's two closing lines: counts and timing, then "ok" or "FAILED: why".
void print_run_summary(const RunContext& run, std::FILE* out);
nlohmann::json run_summary_json(const RunContext& run);

}  // namespace exc::app
