// excavator-bench: speed against accuracy (issues 8 and 14). One run writes the work-precision chart,
// the pressure-integration chart, the fidelity chart, the stability maps and the MuJoCo comparison
// (CSV + PNG each), a summary table on stdout and --json FILE. `excavator-bench export-mjcf` writes the machine as MJCF.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "app/float_environment.hpp"
#include "bench/bench_common.hpp"
#include "bench/bench_runs.hpp"
#include "bench/fidelity_chart.hpp"
#include "output_files/output_file.hpp"
#include "bench/peer_comparison.hpp"
#include "bench/pressure_integration.hpp"
#include "bench/stability_map.hpp"
#include "bench/work_precision.hpp"
#include "bench/mjcf_export.hpp"
#ifdef EXC_HAVE_MUJOCO
#include "bench/mujoco_peer.hpp"
#endif
#include "sim_plant/plant.hpp"
#include "output_files/helper_program.hpp"
#include "option_checks.hpp"

namespace fs = std::filesystem;
using nlohmann::json;

namespace exc::bench {
namespace {

struct Options {
  bool quick = false;
  std::string out = "out/bench";
  std::string json_file;
  std::string scenes_dir = EXC_SOURCE_DIR "/scenes";
  bool plots = true;
  std::string figures;  // where the README's charts go after a complete full run (docs/figures)
};

// The README's and docs' charts of a full run: the file in OUT, the name in the figures directory.
const std::pair<const char*, const char*> kFigures[] = {
    {"work_precision.png", "work_precision.png"},
    {"pressure_integration.png", "pressure_integration.png"},
    {"peer.png", "peer.png"},
    {"fidelity.png", "fidelity.png"},
    {"stability_step.png", "stability_step.png"},
    {"stability_control.png", "stability_control.png"},
    {"stability_valves/stability.png", "stability_valves.png"},
    {"stability_hydraulic_gains/stability.png", "stability_hydraulic_gains.png"},
};

// Copies the charts of a complete run into `dir`, each named; false (and why on stderr) if one is
// missing or cannot be written.
bool copy_figures(const std::string& out, const std::string& dir) {
  bool ok = true;
  std::error_code ec;
  fs::create_directories(dir, ec);
  for (const auto& [from, to] : kFigures) {
    const fs::path src = fs::path(out) / from, dst = fs::path(dir) / to;
    fs::copy_file(src, dst, fs::copy_options::overwrite_existing, ec);
    if (ec) {
      std::fprintf(stderr, "excavator-bench: cannot copy %s to %s: %s\n", src.c_str(), dst.c_str(), ec.message().c_str());
      ok = false;
    } else {
      std::printf("figure: %s\n", dst.c_str());
    }
  }
  return ok;
}

int run_bench(const Options& o) {
  const auto wall0 = std::chrono::steady_clock::now();
  fs::create_directories(o.out);
  // Windows of the tasks that the open-loop runs cover: the dig window starts just before the tip
  // reaches the ground (t = 2 s of the task) so that it digs.
  const double horizon = o.quick ? 0.5 : 3.0;
  std::vector<BenchScene> scenes = {load_bench_scene(o.scenes_dir + "/free_motion.yaml", 0.0, horizon),
                                    load_bench_scene(o.scenes_dir + "/dig.yaml", o.quick ? 2.5 : 1.5, horizon)};
  const std::vector<double> steps = o.quick ? std::vector<double>{1e-2, 1e-3, 1e-4}
                                            : std::vector<double>{1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2e-4, 1e-4, 5e-5, 2e-5, 1e-5};
  const double reference_step = o.quick ? 2e-5 : 2.5e-6;

#ifdef EXC_HAVE_MUJOCO
  std::printf("mujoco: available (%s), peer in this run\n", mujoco_version().c_str());
#else
  std::printf("mujoco: not available, peer skipped (install libmujoco-dev and reconfigure)\n");
#endif

  std::vector<OpenLoopResult> references;
  const std::vector<WorkPoint> work = work_precision(scenes, steps, reference_step, references);
  write_work_csv(o.out + "/work_precision.csv", work);

  const std::vector<PeerResult> peers = peer_comparison(scenes, references, o.out);
  write_peer_csvs(o.out, peers);

  // How the hydraulic machine's pressures are integrated: the dig's commands from a closed-loop run
  // and a four-function valve profile, replayed open loop, against backward Euler at 10 us.
  const std::vector<double> pressure_steps =
      o.quick ? std::vector<double>{1e-2, 1e-3, 2.5e-4}
              : std::vector<double>{1e-2, 5e-3, 2e-3, 1e-3, 5e-4, 2.5e-4, 1e-4, 5e-5, 2.5e-5};
  const PressureChart pressures = pressure_integration(
      {recorded_dig(scenes[1], o.quick ? 1.0 : 10.0), four_functions(scenes[1], o.quick ? 1.0 : 4.0)},
      pressure_steps, 1e-5);
  write_pressure_csv(o.out + "/pressure_integration.csv", pressures);

  const double closed_duration = o.quick ? 1.0 : 0.0;  // 0: the scenes' own durations
  // Three runs of each variant (one with --quick) for the CPU time: the least is kept.
  const std::vector<FidelityRow> fidelity = fidelity_chart(scenes, closed_duration, o.quick ? 1 : 3);
  write_fidelity_csv(o.out + "/fidelity.csv", fidelity);

  // The stability maps: sweep specs (sweeps/stability_*.yaml) through the sweep's shard and merge.
  const StabilityMaps maps = stability_maps(EXC_SOURCE_DIR "/sweeps", o.scenes_dir, o.out, o.quick);
  const std::vector<StepStability>& step_map = maps.step;
  const std::vector<ControlStability>& control_map = maps.control;
  write_stability_csvs(o.out, step_map, control_map);

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
  j["quick"] = o.quick;
  j["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const std::string json_path = o.json_file.empty() ? o.out + "/bench.json" : o.json_file;
  output::write_file(json_path, j.dump(2) + "\n");

  // Summary table.
  std::printf("\n== excavator-bench %s (CSV, PNG and JSON in %s) ==\n", o.quick ? "--quick" : "", o.out.c_str());
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

  for (const HydraulicMap& m : maps.hydraulic) {
    std::printf("\nHydraulic map %s (%s: sweep.csv, stability.png): %d of %d runs failed\n", m.name.c_str(),
                m.dir.c_str(), m.failed, m.runs);
    for (const std::string& line : m.lines) std::printf("  %s\n", line.c_str());
  }

  bool complete = true;
  for (const std::string& name : maps.failed_merges) {
    std::fprintf(stderr, "excavator-bench: the stability map %s lost cases or its chart (above)\n", name.c_str());
    complete = false;
  }
  if (o.plots) {
    const std::vector<std::string> cmd = {"/usr/bin/python3", EXC_BENCH_PLOT_SCRIPT, o.out};
    if (exc::output::run_helper(cmd) != 0) {
      std::fprintf(stderr, "excavator-bench: the plotting script failed (%s); the CSV files are complete\n",
                   exc::output::command_text(cmd).c_str());
      complete = false;
    }
  }
  if (!o.figures.empty()) {
    if (!complete)
      std::fprintf(stderr, "excavator-bench: the run is incomplete (above): the figures in %s are left as they were\n",
                   o.figures.c_str());
    else
      complete = copy_figures(o.out, o.figures);
  }
  std::printf("json: %s (%.1f s wall)\n", json_path.c_str(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count());
  return complete ? 0 : 1;
}

int export_command(const std::string& machine_file, const std::string& out, std::vector<double> q_a) {
  const Machine machine = machine_file.empty() ? reference_machine() : load_machine(machine_file);
  const Model model = build_model(machine);
  Vec4 pose;
  if (q_a.empty()) {
    if (machine.reference_poses.empty())
      throw std::runtime_error(machine.source + ": no reference_poses to assemble at; pass --q-a");
    pose = machine.reference_poses.front().q_a;
  } else {
    for (int i = 0; i < 4; ++i) pose[i] = q_a[i];
  }
  const std::string xml = export_mjcf(model, pose);
  if (out == "-") {
    std::cout << xml;
  } else {
    output::write_file(out, xml);
    std::fprintf(stderr, "export-mjcf: wrote %s\n", out.c_str());
  }
  return 0;
}

}  // namespace
}  // namespace exc::bench

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-bench", 1);  // stdout lost to a full disk is not exit 0
  // The plant, the firmware and the peer all in the loop's floating-point mode (docs/floating-point.md).
  exc::app::set_loop_float_mode();
  CLI::App app{
      "excavator-bench: work-precision chart, pressure-integration chart, fidelity chart, stability maps and MuJoCo as "
      "a peer.\n"
      "Without a subcommand it runs the whole benchmark (about 10 min; --quick: under 1 min)."};
  exc::bench::Options o;
  app.add_flag("--quick", o.quick, "CI mode: fewer step sizes and shorter horizons (< 1 min)");
  app.add_option("--out", o.out, "directory for the CSV and PNG files")->capture_default_str();
  app.add_option("--json", o.json_file, "write the summary JSON here (default: OUT/bench.json)");
  app.add_option("--scenes", o.scenes_dir, "directory holding free_motion.yaml and dig.yaml")->capture_default_str();
  bool no_plots = false;
  auto* no_plots_flag = app.add_flag("--no-plots", no_plots, "write the CSV files only");
  app.add_option("--figures", o.figures,
                 "after a complete full run, copy the README's charts into this directory (docs/figures: the one "
                 "command that regenerates them, docs/bench.md)")
      ->excludes("--quick")
      ->excludes(no_plots_flag);
  auto* exp = app.add_subcommand("export-mjcf", "write the machine as MJCF (MuJoCo XML), loops as connect equalities");
  std::string machine_file, xml_out = "-";
  std::vector<double> q_a;
  exp->add_option("--machine", machine_file, "machine file (default: the built-in reference machine)");
  exp->add_option("-o,--output", xml_out, "output file ('-': stdout)")->capture_default_str();
  exp->add_option("--q-a", q_a, "assemble at q_a = swing L_boom L_arm L_bucket (default: the first reference pose)")
      ->expected(4);
  app.require_subcommand(0, 1);
  if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;
  o.plots = !no_plots;
  try {
    if (exp->parsed()) return exc::bench::export_command(machine_file, xml_out, q_a);
    return exc::bench::run_bench(o);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "excavator-bench: %s\n", e.what());
    return 1;
  }
}
