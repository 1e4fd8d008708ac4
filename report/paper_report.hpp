#pragma once
// The paper's whole figure set from the main job: the free-motion scene (its Figs. 4-7) and the
// digging scene (Figs. 8-12) with the paper's force actuators, each run with PID and the adaptive law,
// and one report page that puts every figure under the paper's number with what the paper shows and
// what this run measured; then the same dig through a hydraulic machine's valves (PID, adaptive,
// flow-based control), what the paper's claim becomes on the machine a firmware really drives.
#include <filesystem>

#include "scene_job.hpp"

namespace exc::sim {

// Writes out/report.md from the two scenes' results (their own reports hold the PNGs). Returns false
// when it cannot write the file.
bool write_paper_report(const std::filesystem::path& out, const SceneJobResult& free_motion, const SceneJobResult& dig,
                        const SceneJobResult& hydraulic_dig);

}  // namespace exc::sim
