#include "run_report.hpp"

#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

#include "app/run_summary.hpp"
#include "output_files/helper_program.hpp"

namespace exc::sim {
namespace {

constexpr const char* kJoints[4] = {"swing", "boom", "arm", "bucket"};
constexpr const char* kUnits[4] = {"rad", "m", "m", "m"};
constexpr const char* kTheta[6] = {"M_x", "B_x", "K_x", "M_z", "B_z", "K_z"};

nlohmann::json per_joint(const double (&v)[4]) {
  nlohmann::json j;
  for (int i = 0; i < 4; ++i) j[kJoints[i]] = v[i];
  return j;
}

// printf into a string of any length (a failure reason may be long).
std::string format(const char* fmt, ...) __attribute__((format(printf, 1, 2)));
std::string format(const char* fmt, ...) {
  va_list args;
  va_start(args, fmt);
  va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, fmt, args);
  va_end(args);
  std::string text(size > 0 ? size : 0, '\0');
  if (size > 0) std::vsnprintf(text.data(), text.size() + 1, fmt, again);
  va_end(again);
  return text;
}

nlohmann::json timing_json(const Timing& t) {
  return {{"median", t.median_us}, {"p99", t.p99_us}, {"max", t.max_us}, {"count", t.count}};
}

}  // namespace

nlohmann::json tracked_per_joint(const RunResult& r, const double (&v)[4]) {
  return r.tracking_samples > 0 ? per_joint(v) : nlohmann::json(nullptr);
}

// Work cycles: one row per cycle and controller, when the task repeats.
void print_cycles(const Summary& summary, std::ostream& out) {
  std::size_t most = 0;
  for (const RunRecord& r : summary.runs) most = std::max(most, r.cycles.size());
  if (most < 2) return;
  out << "\nper work cycle: RMS error (mm; swing mrad), worst bucket error, peak soil force, K_x estimate at the end\n";
  out << format("%-6s %-10s %8s %8s %8s %8s %10s %10s %10s %10s\n", "cycle", "controller", "swing", "boom", "arm",
                "bucket", "bucket max", "time (s)", "soil (kN)", "K_x est");
  for (std::size_t c = 0; c < most; ++c)
    for (const RunRecord& r : summary.runs) {
      if (c >= r.cycles.size()) continue;
      const CycleRecord& k = r.cycles[c];
      out << format("%-6zu %-10s %8.3f %8.3f %8.3f %8.3f %10.2f %10.2f %10.1f %10.4g\n", c + 1, r.controller.c_str(),
                    k.rms_error[0] * 1e3, k.rms_error[1] * 1e3, k.rms_error[2] * 1e3, k.rms_error[3] * 1e3,
                    k.max_error[3] * 1e3, k.end - k.start, k.peak_soil_force * 1e-3, k.theta_hat[2]);
    }
}

void print_summary(const Summary& summary, std::ostream& out) {
  out << "\nscene " << summary.scene << ": " << summary.setup << "\n\n";
  out << "tracking error (while tracking)     ";
  for (const RunResult& r : summary.runs) {
    out << format("| %-10s RMS      max     ", r.controller.c_str());
  }
  out << "\n";
  for (int j = 0; j < 4; ++j) {
    out << format("  %-7s (%-3s)                     ", kJoints[j], kUnits[j]);
    for (const RunResult& r : summary.runs)
      out << (r.tracking_samples > 0 ? format("| %10.3e %10.3e    ", r.rms_error[j], r.max_error[j])
                                     : format("| %10s %10s    ", "n/a", "n/a"));
    out << "\n";
  }
  bool any_hold = false, any_stop = false;
  // Only after a task began: a run that never tracked held no pose it was given (its figures are n/a).
  for (const RunResult& r : summary.runs) {
    any_hold = any_hold || (r.tracking_samples > 0 && (r.hold.samples > 0 || r.settle.samples > 0));
    any_stop = any_stop || (r.tracking_samples > 0 && r.stop.samples > 0);
  }
  // The other phases: the hold (after the task, after a stop, at start-up) against the holding
  // tolerance the verdict applies, and the safe state's creep.
  auto phase_rows = [&](const char* title, PhaseErrors RunResult::*phase) {
    out << title;
    for (const RunResult& r : summary.runs) out << format("| %-10s RMS      max     ", r.controller.c_str());
    out << "\n";
    for (int j = 0; j < 4; ++j) {
      out << format("  %-7s (%-3s)                     ", kJoints[j], kUnits[j]);
      for (const RunResult& r : summary.runs) {
        const PhaseErrors& p = r.*phase;
        out << (p.samples > 0 && r.tracking_samples > 0 ? format("| %10.3e %10.3e    ", p.rms_error[j], p.max_error[j])
                              : format("| %10s %10s    ", "n/a", "n/a"));
      }
      out << "\n";
    }
  };
  if (any_hold) {
    phase_rows(format("\nhold error (holding a pose once settled; tolerance %.1f mm, %.1f mrad swing)",
                      kHoldingTolerance[1] * 1e3, kHoldingTolerance[0] * 1e3).c_str(), &RunResult::hold);
    out << "  excursions past it (boom/arm/bucket)";
    for (const RunResult& r : summary.runs)
      out << format("| %-25s", format("%llu / %llu / %llu", static_cast<unsigned long long>(r.hold.excursions[1]),
                                       static_cast<unsigned long long>(r.hold.excursions[2]),
                                       static_cast<unsigned long long>(r.hold.excursions[3])).c_str());
    out << "\n";
  }
  if (any_hold) {
    phase_rows(format("\nsettle error (a hold's start: until every function stayed inside half the tolerance for %.1f s, at most %.0f s)",
                      kHoldSettleDwell, kHoldSettleLimit).c_str(), &RunResult::settle);
    out << "  settling time (s)                  ";
    for (const RunResult& r : summary.runs) out << format("| %-25.2f", r.settle.seconds);
    out << "\n";
  }
  if (any_stop) phase_rows("\nstop error (the safe state: valves centred)", &RunResult::stop);
  print_cycles(summary, out);
  out << "\nsoil estimates at the end (true value)\n";
  for (int i = 0; i < 6; ++i) {
    out << format("  %-4s true %10.4g   ", kTheta[i], summary.runs.empty() ? 0.0 : summary.runs[0].theta_true[i]);
    for (const RunResult& r : summary.runs) out << format("| %-10s %10.4g ", r.controller.c_str(), r.theta_hat[i]);
    out << "\n";
  }
  out << "\n";
  for (const RunResult& r : summary.runs) {
    const std::string task =
        r.task_finished ? format("task finished at %.3f s", r.task_finish_time) : std::string("task not finished");
    out << format("%-10s %s; peak soil force %8.1f kN, %d shear re-anchorings; control step median %.1f us, p99 %.1f us, "
                  "max %.1f us; heap allocations in loop %llu; telemetry %llu messages, %llu dropped; "
                  "%.1f s simulated in %.3g s (%.0fx real time)\n",
                  r.controller.c_str(), task.c_str(), r.peak_soil_force * 1e-3, r.reanchor_count,
                  r.control_step.median_us, r.control_step.p99_us, r.control_step.max_us,
                  static_cast<unsigned long long>(r.heap_allocations_in_loop),
                  static_cast<unsigned long long>(r.telemetry_published), static_cast<unsigned long long>(r.telemetry_dropped),
                  r.simulated_seconds, r.wall_seconds, r.wall_seconds > 0 ? r.simulated_seconds / r.wall_seconds : 0.0);
    if (r.telemetry_per_cycle_every > 1)
      out << format("%-10s telemetry: EXC_STATE, EXC_COMMAND and EXC_CONTROLLER logged every %u cycles (--log-every), "
                    "the figures above from every cycle\n",
                    "", static_cast<unsigned>(r.telemetry_per_cycle_every));
    if (r.hydraulic)
      out << format("%-10s hydraulics: chamber pressures %.2f .. %.1f MPa; pumps short of flow %.2f s (firmware asked more "
                    "in %llu cycles); reliefs open %.3f s; make-up at the vapour floor %.3f s\n",
                    "", r.min_pressure * 1e-6, r.peak_pressure * 1e-6, r.flow_saturated_seconds,
                    static_cast<unsigned long long>(r.pump_limited_cycles), r.relief_seconds, r.cavitation_seconds);
    if (r.target) {
      const TargetFigures& t = *r.target;
      out << format("%-10s on %s: instructions per cycle median %llu, p99 %llu, max %llu (cycle %llu); per stage (max):", "",
                    t.name.c_str(), static_cast<unsigned long long>(t.per_cycle().median),
                    static_cast<unsigned long long>(t.per_cycle().p99), static_cast<unsigned long long>(t.per_cycle().max),
                    static_cast<unsigned long long>(t.worst_cycle));
      for (int s = 0; s + 1 < app::kTargetStages; ++s)
        out << format(" %s %llu", app::kTargetStageNames[s], static_cast<unsigned long long>(t.stages[static_cast<std::size_t>(s)].max));
      out << format("; stack %llu of %llu bytes; flash %llu bytes, RAM %llu bytes; heap calls after start-up %llu\n",
                    static_cast<unsigned long long>(t.stack_bytes), static_cast<unsigned long long>(t.stack_size_bytes),
                    static_cast<unsigned long long>(t.flash_bytes), static_cast<unsigned long long>(t.ram_bytes),
                    static_cast<unsigned long long>(t.heap_calls_after_start_up));
    }
    if (!r.ok) out << "  FAILED: " << r.failure << "\n";
  }
}

// A run on an emulated target: the image's instructions per cycle and per stage, stack, size, heap.
nlohmann::json target_json(const TargetFigures& t) {
  auto figures = [](const InstructionFigures& f) {
    return nlohmann::json{{"median", f.median}, {"p99", f.p99}, {"max", f.max}, {"cycles", f.cycles}};
  };
  nlohmann::json stages;
  for (int s = 0; s + 1 < app::kTargetStages; ++s) stages[app::kTargetStageNames[s]] = figures(t.stages[static_cast<std::size_t>(s)]);
  return {{"name", t.name},
          {"image", t.image},
          {"instructions_per_cycle", figures(t.per_cycle())},
          {"worst_cycle", t.worst_cycle},
          {"instructions_per_stage", stages},
          {"stack_bytes", t.stack_bytes},
          {"stack_size_bytes", t.stack_size_bytes},
          {"flash_bytes", t.flash_bytes},
          {"ram_bytes", t.ram_bytes},
          {"heap_calls_after_start_up", t.heap_calls_after_start_up},
          {"start_up_instructions", t.start_up_instructions}};
}

nlohmann::json stop_json(const StopJudgement& s) {
  auto four = [](const std::array<double, 4>& a) { return nlohmann::json{a[0], a[1], a[2], a[3]}; };
  nlohmann::json exempt = nlohmann::json::array();
  for (const StopExemption& e : s.exempt)
    exempt.push_back({{"function", kActiveNames[static_cast<std::size_t>(e.function)]}, {"reason", e.reason}, {"travel", e.travel}});
  nlohmann::json j = {{"detected_after_s", s.detected_after_s},
                      {"onset_after_s", s.onset_after_s >= 0 ? nlohmann::json(s.onset_after_s) : nlohmann::json(nullptr)},
                      {"detected_after_onset_s", s.detected_after_onset_s},
                      {"outputs_after_s", s.outputs_after_s},
                      {"peak_speed_after_detection", four(s.peak_speed)},
                      {"travel_to_first_stop", four(s.travel)},
                      {"travel_allowed", four(s.travel_allowed)},
                      {"first_overshoot", four(s.first_overshoot)},
                      {"drift_after_1_5_s", four(s.drift)},
                      {"drift_fit_span_s", s.drift_span},
                      {"ring_tau_s", four(s.ring_tau)},
                      {"brake_after_s", s.brake_after_s >= 0 ? nlohmann::json(s.brake_after_s) : nlohmann::json(nullptr)},
                      {"exempt", exempt},
                      {"meets_r1", s.meets_r1},
                      {"meets_r2", s.meets_r2},
                      {"meets_r3", s.meets_r3}};
  if (!s.why.empty()) j["why"] = s.why;
  return j;
}

nlohmann::json to_json(const Summary& summary) {
  nlohmann::json j;
  j["scene"] = summary.scene;
  j["setup"] = summary.setup;
  j["ok"] = summary.all_ok;
  if (summary.interrupted) j["interrupted"] = true;
  Timing worst;
  std::uint64_t allocations = 0;
  double simulated = 0;
  for (const RunResult& r : summary.runs) {
    nlohmann::json run;
    run["ok"] = r.ok;
    if (!r.ok) run["failure"] = r.failure;
    run["rms_error"] = tracked_per_joint(r, r.rms_error);
    run["max_error"] = tracked_per_joint(r, r.max_error);
    run["tracking"] = {{"rms_error", tracked_per_joint(r, r.measured_rms_error)}, {"max_error", tracked_per_joint(r, r.measured_max_error)}};
    run["tracking_samples"] = r.tracking_samples;
    // Every phase (the figures above are the tracking phase's): tracking, hold, stop; and the
    // tolerance the verdict holds the hold to.
    run["phases"] = app::phases_json(r.tracking, r.settle, r.hold, r.stop);
    run["holding_tolerance"] = app::holding_tolerance_json();
    run["hold_ok"] = app::hold_failure(r.hold).empty();
    run["hold_settle_limit_seconds"] = kHoldSettleLimit;
    nlohmann::json theta_hat, theta_true;
    for (int i = 0; i < 6; ++i) {
      theta_hat[kTheta[i]] = r.theta_hat[i];
      theta_true[kTheta[i]] = r.theta_true[i];
    }
    run["theta_hat"] = theta_hat;
    run["theta_true"] = theta_true;
    run["peak_soil_force"] = r.peak_soil_force;
    run["reanchor_count"] = r.reanchor_count;
    run["control_step_us"] = timing_json(r.control_step);
    run["firmware_cycle_us"] = timing_json(r.firmware_cycle);
    run["heap_allocations_in_loop"] = r.heap_allocations_in_loop;
    run["simulated_seconds"] = r.simulated_seconds;
    run["wall_seconds"] = r.wall_seconds;
    run["safe_stops"] = r.safe_stops;
    run["can_frames_rejected"] = r.rx_rejected;
    if (r.hydraulic)
      run["hydraulics"] = {{"peak_pressure", r.peak_pressure},
                           {"min_pressure", r.min_pressure},
                           {"flow_saturated_seconds", r.flow_saturated_seconds},
                           {"pump_limited_cycles", r.pump_limited_cycles},
                           {"relief_seconds", r.relief_seconds},
                           {"cavitation_seconds", r.cavitation_seconds}};
    run["task_finished"] = r.task_finished;
    if (r.task_finished) run["task_finish_time"] = r.task_finish_time;
    if (r.target) run["target"] = target_json(*r.target);
    if (r.stop_judgement) run["stop"] = stop_json(*r.stop_judgement);
    nlohmann::json cycles = nlohmann::json::array();
    for (const CycleRecord& k : r.cycles) {
      nlohmann::json theta;
      for (int i = 0; i < 6; ++i) theta[kTheta[i]] = k.theta_hat[i];
      cycles.push_back({{"start", k.start}, {"end", k.end}, {"rms_error", per_joint(k.rms_error)},
                        {"max_error", per_joint(k.max_error)}, {"peak_soil_force", k.peak_soil_force},
                        {"theta_hat", theta}});
    }
    run["cycles"] = cycles;
    run["telemetry"] = {{"enqueued", r.telemetry_enqueued}, {"published", r.telemetry_published},
                        {"dropped", r.telemetry_dropped}, {"ring_high_water", r.telemetry_ring_high_water},
                        {"overflow_policy", "block"}, {"per_cycle_every", r.telemetry_per_cycle_every}};
    j[r.controller] = run;
    // Headline figures over all runs: the worst timing, the total allocations.
    worst.median_us = std::max(worst.median_us, r.control_step.median_us);
    worst.p99_us = std::max(worst.p99_us, r.control_step.p99_us);
    worst.max_us = std::max(worst.max_us, r.control_step.max_us);
    worst.count += r.control_step.count;
    allocations += r.heap_allocations_in_loop;
    simulated = std::max(simulated, r.simulated_seconds);
  }
  j["control_step_us"] = timing_json(worst);
  j["heap_allocations_in_loop"] = allocations;
  j["simulated_seconds"] = simulated;
  return j;
}

int write_report(const std::filesystem::path& log, const std::filesystem::path& out_dir,
                 const std::filesystem::path& summary_json, const std::string& title) {
  return output::run_helper({EXC_LOG_TOOL, "report", log.string(), "--out", (out_dir / "report").string(), "--summary",
                             summary_json.string(), "--title", title});
}

int plot_robustness(const std::filesystem::path& json, const std::filesystem::path& out_dir) {
  return output::run_helper({EXC_PLOT_RUN, "--robustness", json.string(), "--out", out_dir.string()});
}

}  // namespace exc::sim
