#pragma once
// The main job's outputs: the summary table on stdout, the JSON for machines, and the report page
// (CSV export + plots by excavator-log report).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <ostream>
#include <string>

#include "in_process_run.hpp"

namespace exc::sim {

void print_summary(const Summary& summary, std::ostream& out);
// A run's tracking figure per joint ({swing, boom, arm, bucket}), null when the run never tracked
// (a metric of no samples is not 0): the summary's and the sweeps' records.
nlohmann::json tracked_per_joint(const RunResult& r, const double (&v)[4]);
nlohmann::json to_json(const Summary& summary);
// A faulted run's stop against R1-R3 (harness/stop_judge.hpp): the summary's and the campaign's
// `stop` block, per function in the order swing, boom, arm, bucket.
nlohmann::json stop_json(const StopJudgement& s);
// Runs `excavator-log report` on the run's log into out_dir/report; returns its exit status.
int write_report(const std::filesystem::path& log, const std::filesystem::path& out_dir,
                 const std::filesystem::path& summary_json, const std::string& title);
// Runs `plot-run --robustness JSON --out DIR` (robustness.png); returns its exit status.
int plot_robustness(const std::filesystem::path& json, const std::filesystem::path& out_dir);

}  // namespace exc::sim
