#pragma once
// The fault campaign (docs/sweeps.md): a sweep whose cases each carry one random fault.
// Kept apart from the sweep's reading, sharding and merging (sweep.cpp): the fault a case draws, the
// schedule the harness injects, a run's outcome, and the merge's count of outcomes per controller
// and fault kind.
#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "sweep.hpp"

namespace exc::sim {

// Draws case c's fault from the case's generator: its kind from `kinds`, its start, length, joint
// and size (ranges in docs/sweeps.md).
// s a stopped campaign run may run past its scene to see the machine come to rest (LockstepOptions::
// rest_horizon): twice the 1.5 s the safety concept asks, and the engine's 1 s run-down, with room.
inline constexpr double kCampaignRestHorizon = 6.0;

void draw_fault(std::mt19937_64& rng, const std::vector<std::string>& kinds, SweepCase& c);
// Refuses a fault the scene cannot take (pump_loss without the hydraulic machine), before any run.
void check_faults_fit(const std::vector<std::string>& kinds, const SceneBundle& scene);
// The schedule the harness injects for case c (none for a case without a fault).
FaultSchedule fault_schedule(const SweepCase& c, std::uint64_t seed);

// A run's outcome as the campaign counts it, with the times it was judged by:
//   tracked     no safe stop, and the true error within controller.tracking_error_limit throughout
//   safe_state  the firmware took the safe state within controller.watchdog_timeout of detecting the
//               fault (FirmwareNode::fault_detected_time) and the machine's stop met R3 (travel,
//               drift, ring, swing brake; harness/stop_judge.hpp), or its one miss is a declared
//               gravity exemption
//   neither     anything else (the plant stopped, never tracked, beyond the limits without a stop, a
//               late safe state, a stop that misses R3), with the reason in "why"
nlohmann::json run_outcome(const RunRecord& r, const app::FirmwareSettings& firmware);

// Counts the run of `controller` in a merged case line (one with a "fault") into `table`, the
// campaign's rows by controller and fault kind: runs, outcomes, the worst times to the safe state
// from the fault's start and from its detection, the cases that ended neither way, and per scene.
void count_campaign_run(nlohmann::json& table, const nlohmann::json& line, const std::string& controller);
// The same runs per safety function (docs/safety.md): keyed by the firmware fault that took the
// first stop (the monitor that found it), each row the runs, the fault kinds behind them, the worst
// detection and the worst time to rest from the fault's start, the runs never at rest, the
// emergency stops; runs without a stop under "none".
void count_safety_function(nlohmann::json& table, const nlohmann::json& line, const std::string& controller);

}  // namespace exc::sim
