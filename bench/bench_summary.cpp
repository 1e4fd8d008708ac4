// excavator-bench's summary: the JSON file's figures and the table on stdout (bench/bench_summary.hpp).
#include "bench_summary.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "bench_common.hpp"

namespace exc::bench {

nlohmann::json summary_json(const BenchResults& r) {
  using nlohmann::json;
  const std::vector<WorkPoint>& work = r.work;
  const std::vector<PeerResult>& peers = r.peers;
  const PressureChart& pressures = r.pressures;
  const std::vector<FidelityRow>& fidelity = r.fidelity;
  // Headline numbers: the free-motion scene (the dig scene's figures are in peer.csv).
  const PeerResult& head = peers.front();
  json j;
  j["plant_step_us"] = number_or_null(head.plant_step_us);
  j["mujoco_step_us"] = number_or_null(head.mujoco_step_us);
  j["constraint_error"] = number_or_null(head.constraint_error);
  j["mujoco_constraint_error"] = number_or_null(head.mujoco_constraint_error);
  j["control_step_us"] = number_or_null(head.control_step_us);
  j["mujoco_inverse_us"] = number_or_null(head.mujoco_inverse_us);
  j["plant_dynamics_step_us"] = number_or_null(head.dynamics_step_us);
  j["mujoco"] = head.mujoco_status;
  j["step_speed_ratio"] = number_or_null(head.mujoco_step_us / head.plant_step_us);
  j["constraint_error_ratio"] = number_or_null(head.mujoco_constraint_error / std::max(head.constraint_error, 1e-16));
  j["control_speed_ratio"] = number_or_null(head.mujoco_inverse_us / head.control_step_us);
  j["pareto"] = json::array();
  for (const WorkPoint& p : work)
    if (p.pareto)
      j["pareto"].push_back({{"scene", p.scene}, {"method", p.method}, {"step_s", p.step},
                             {"cpu_s_per_sim_s", p.cpu_per_s}, {"tip_rms_m", p.tip_rms}});
  j["scenes"] = json::array();
  for (const PeerResult& p : peers)
    j["scenes"].push_back({{"scene", p.scene}, {"plant_step_us", number_or_null(p.plant_step_us)},
                           {"plant_tip_rms_m", number_or_null(p.tip_rms)},
                           {"constraint_error", number_or_null(p.constraint_error)},
                           {"augmented_baumgarte_constraint_error", number_or_null(p.augmented_constraint_error)},
                           {"mujoco_step_us", number_or_null(p.mujoco_step_us)},
                           {"mujoco_constraint_error", number_or_null(p.mujoco_constraint_error)},
                           {"mujoco_tip_rms_m", number_or_null(p.mujoco_tip_rms)},
                           {"control_step_us", number_or_null(p.control_step_us)},
                           {"inverse_dynamics_us", number_or_null(p.inverse_dynamics_us)},
                           {"plant_dynamics_step_us", number_or_null(p.dynamics_step_us)},
                           {"mujoco_inverse_us", number_or_null(p.mujoco_inverse_us)}});
  j["pressure_integration"] = json::array();
  for (const ExplicitBoundary& b : pressures.boundaries)
    j["pressure_integration"].push_back({{"input", b.input},
                                         {"reference_step_s", pressures.reference_step},
                                         {"forward_euler_largest_passing_step_s", b.stable > 0 ? json(b.stable) : json()},
                                         {"forward_euler_smallest_failing_step_s", b.failing > 0 ? json(b.failing) : json()},
                                         {"forward_euler_failure", b.failure}});
  j["recommended_fidelity"] = json::object();
  for (const FidelityRow& r : fidelity)
    if (r.recommended) j["recommended_fidelity"][r.scene] = r.fidelity;
  j["tolerances"] = {{"tip_rms_m", kTipTolerance}, {"force_rel", kForceTolerance}, {"tracking_m", kTrackingTolerance}};
  return j;
}

void print_summary(const BenchResults& r, bool quick, const std::string& out) {
  const std::vector<WorkPoint>& work = r.work;
  const std::vector<PeerResult>& peers = r.peers;
  const PressureChart& pressures = r.pressures;
  const std::vector<FidelityRow>& fidelity = r.fidelity;
  const std::vector<StepStability>& step_map = r.maps.step;
  const std::vector<ControlStability>& control_map = r.maps.control;
  const PeerResult& head = peers.front();
  // Summary table.
  std::printf("\n== excavator-bench %s (CSV, PNG and JSON in %s) ==\n", quick ? "--quick" : "", out.c_str());
  std::printf("%-12s %-8s %12s %16s %16s %14s\n", "scene", "engine", "step (us)", "constraint (m)", "tip vs ref (m)",
              "control (us)");
  for (const PeerResult& p : peers) {
    std::printf("%-12s %-8s %12.2f %16.3g %16.3g %14.2f\n", p.scene.c_str(), "plant", p.plant_step_us,
                p.constraint_error, p.tip_rms, p.control_step_us);
    std::printf("%-12s %-8s %12.2f %16.3g %16.3g %14.2f   (mj_inverse; %s)\n", p.scene.c_str(), "mujoco",
                p.mujoco_step_us, p.mujoco_constraint_error, p.mujoco_tip_rms, p.mujoco_inverse_us,
                p.mujoco_status.c_str());
  }
  for (const PeerResult& p : peers)
    std::printf("%-12s %-8s %12.2f   (integrator step alone: dynamics + Euler, no sensors/checks; our inverse "
                "dynamics %.2f us)\n", p.scene.c_str(), "plant", p.dynamics_step_us, p.inverse_dynamics_us);
  std::printf("ratios (free motion): mj_step / plant step = %.2f (target >= 2), constraint error MuJoCo / plant = "
              "%.3g (target >= 100), mj_inverse / control step = %.2f (target > 1); mj_step / integrator step = %.2f\n",
              head.mujoco_step_us / head.plant_step_us,
              head.mujoco_constraint_error / std::max(head.constraint_error, 1e-16),
              head.mujoco_inverse_us / head.control_step_us, head.mujoco_step_us / head.dynamics_step_us);
  std::printf("\nPareto front (work-precision, tip RMS against CPU per simulated second):\n");
  for (const WorkPoint& p : work)
    if (p.pareto)
      std::printf("  %-12s %-40s %-8s %10.3g s/s %12.3g m\n", p.scene.c_str(), p.method.c_str(), step_label(p.step).c_str(),
                  p.cpu_per_s, p.tip_rms);
  std::printf("\nPressure integration (open loop, valve commands held 10 ms; against backward Euler at %s):\n",
              step_label(pressures.reference_step).c_str());
  for (const PressurePoint& p : pressures.points)
    std::printf("  %-18s %-15s %-8s %s cpu %8.3g s/s tip %9.3g m pressures %9.3g MPa %5.1f iterations %s\n",
                p.input.c_str(), p.method.c_str(), step_label(p.step).c_str(), p.ok ? "ok  " : "FAIL", p.cpu_per_s,
                p.tip_rms, p.pressure_rms * 1e-6, p.iterations, p.failure.substr(p.failure.find(": ") + 1, 60).c_str());
  for (const ExplicitBoundary& b : pressures.boundaries)
    std::printf("  %-18s forward_euler: largest substep passed %s, smallest stopped by the checks %s\n", b.input.c_str(),
                b.stable > 0 ? step_label(b.stable).c_str() : "none", b.failing > 0 ? step_label(b.failing).c_str() : "none");
  std::printf("\nFidelity (closed loop, adaptive; tolerance: tip %.0f mm, forces %.0f %%, tracking %.0f mm):\n",
              kTipTolerance * 1e3, kForceTolerance * 100, kTrackingTolerance * 1e3);
  for (const FidelityRow& r : fidelity)
    std::printf("  %-12s %-54s %s cpu %8.3g s/s (%5.1f %% of the reference's) tip %6.2f mm force %5.1f %% tracking "
                "%6.2f mm %s%s\n", r.scene.c_str(), r.fidelity.c_str(), r.ok ? "ok  " : "FAIL", r.cpu_per_s,
                100 * r.cost_ratio, 1e3 * r.tip_rms, 100 * r.force_rel, 1e3 * r.tracking_diff,
                r.reference ? "(reference) " : "", r.recommended ? "<- recommended" : r.failure.substr(0, 70).c_str());
  std::printf("\nLargest stable step (plant checks) against soil stiffness and joint speed:\n");
  for (const StepStability& r : step_map)
    std::printf("  %-42s %-24s %10.3g  %s\n", r.method.c_str(), r.axis.c_str(), r.value,
                std::isfinite(r.largest_stable_step) ? step_label(r.largest_stable_step).c_str() : "none");
  std::printf("\nController stability (dig scene; ok = no plant check and no safe stop):\n");
  for (const ControlStability& r : control_map)
    std::printf("  %-10s %-18s %10.3g  %-4s tracking %9.3g %s\n", r.controller.c_str(), r.axis.c_str(), r.value,
                r.ok ? "ok" : "FAIL", r.tracking, r.failure.substr(0, 70).c_str());

  for (const HydraulicMap& m : r.maps.hydraulic) {
    std::printf("\nHydraulic map %s (%s: sweep.csv, stability.png): %d of %d runs failed\n", m.name.c_str(),
                m.dir.c_str(), m.failed, m.runs);
    for (const std::string& line : m.lines) std::printf("  %s\n", line.c_str());
  }

}

}  // namespace exc::bench
