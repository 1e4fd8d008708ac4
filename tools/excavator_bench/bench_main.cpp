// excavator-bench: speed against accuracy. One run writes the work-precision chart,
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
#include "bench/bench_summary.hpp"
#include "bench/work_precision.hpp"
#include "bench/mjcf_export.hpp"
#ifdef EXC_HAVE_MUJOCO
#include "bench/mujoco_peer.hpp"
#endif
#include "sim_plant/plant.hpp"
#include "output_files/helper_program.hpp"
#include "option_checks.hpp"
#include "model/machine_reader.hpp"

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

  const BenchResults results{work, peers, pressures, fidelity, maps};
  json j = summary_json(results);
  j["quick"] = o.quick;
  j["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const std::string json_path = o.json_file.empty() ? o.out + "/bench.json" : o.json_file;
  output::write_file(json_path, j.dump(2) + "\n");

  print_summary(results, o.quick, o.out);

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
