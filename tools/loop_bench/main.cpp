// excavator-loop-bench: the closed loop's real-time factor. The dig scene's whole
// in-process loop (firmware, CAN codec and in-memory bus, plant, lossless telemetry into an LCM log)
// through the harness every tool uses, medians over repeats; the floor the loop's two model
// evaluations set (the plant's forward dynamics, the firmware's M_a and h_a) on the same run's
// states; and, with --split, the per-stage instruction split of one cycle (callgrind). Build Release.
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/float_environment.hpp"
#include "bench/closed_loop_bench.hpp"
#include "control/controller_registry.hpp"
#include "model/scene_common.hpp"
#include "option_checks.hpp"
#include "output_files/output_file.hpp"

using namespace exc;
using bench::median;

int main(int argc, char** argv) {
  exc::output::check_stdout_at_exit("excavator-loop-bench", 1);  // stdout lost to a full disk is not exit 0
  exc::app::set_loop_float_mode();  // the floor's model evaluations and replays as the loop runs them
  CLI::App app{"The closed loop's real-time factor: the dig scene's firmware, CAN and plant in one process with "
               "every telemetry message recorded, medians over repeats; the floor of its model evaluations; "
               "--split: the per-stage instruction split of one cycle under callgrind.",
               "excavator-loop-bench"};
  std::string scene_path = std::string(EXC_SOURCE_DIR_BENCH) + "/scenes/dig.yaml";
  std::string controller = "adaptive";
  double duration = 0, split_duration = 2, history = 600;
  int repeats = 7;
  bool split = false, child = false, pin = true, general = true;
  int child_model = 0;
  app.add_option("--scene", scene_path, "scene (default: scenes/dig.yaml)");
  app.add_option("--controller", controller, "controller kind (default adaptive)");
  app.add_option("--duration", duration, "simulated seconds per run (default: the scene's)")
      ->check(exc::cli::number_in(exc::kRunDurationBounds, "s"));
  app.add_option("--repeats", repeats, "runs per figure; medians are printed (default 7)")
      ->check(exc::cli::count_in(1, 1000));
  app.add_flag("--split", split, "also the per-stage instruction split (runs itself under valgrind --tool=callgrind)");
  app.add_option("--split-duration", split_duration, "simulated seconds of the callgrind run (default 2)")
      ->check(exc::cli::number_in({0.01, 600}, "s"));
  app.add_option("--history", history,
                 "simulated seconds of a long run without telemetry whose first and last seconds are compared, in "
                 "the loop's floating-point mode and with gradual underflow (default 600; 0: none)")
      ->check(exc::cli::number_in({0, 28800}, "s"));
  app.add_flag("!--no-pin", pin, "do not pin the process (loop and telemetry thread) to one core");
  app.add_flag("!--no-general", general, "leave out the general closed-chain path (the code before the planar one) "
               "that every figure is otherwise measured beside");
  app.add_flag("--child", child, "one run with telemetry and nothing printed (what --split profiles)")->group("");
  app.add_option("--child-model", child_model, "evaluate the model on this many states and print nothing (--split)")
      ->group("");
    if (const auto status = exc::cli::parse_command_line(app, argc, argv)) return *status;

  if (!control::controller_registry().find(controller)) {
    std::fprintf(stderr, "excavator-loop-bench: unknown controller '%s' (allowed: %s)\n", controller.c_str(),
                 control::controller_registry().names().c_str());
    return 2;
  }
  if (pin) {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(std::max(0, sched_getcpu()), &one);
    sched_setaffinity(0, sizeof one, &one);  // every thread started from here on shares the core
  }
  try {
    const double load0 = bench::cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    const sim::SceneBundle bundle = sim::load_scene_bundle(scene_path);
    const double load_s = bench::cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - load0;
    sim::LockstepOptions options;
    options.controller = controller;
    options.duration = duration;
    const std::string log = "/tmp/loop-bench-" + std::to_string(getpid()) + ".lcm";
    if (child) {
      options.duration = split_duration;
      bench::closed_loop_run(bundle, options, true, log);
      return 0;
    }
    if (child_model > 0) return bench::evaluate_model_paths(bundle, static_cast<std::size_t>(child_model)) ? 0 : 1;
    const double seconds = duration > 0 ? duration : bundle.scene.duration;
    std::printf("# Closed loop: %s, %s, %.1f s simulated, %d repeats (scene loading, effort-feasibility check "
                "included: %.2f s CPU, once)\n\n",
                bundle.name.c_str(), controller.c_str(), seconds, repeats, load_s);
    // Every figure with the planar path (now) and, unless --no-general, the general one (before), the
    // runs alternating so that load that comes and goes meets all of them.
    std::vector<ClosedChainPath> paths = {ClosedChainPath::planar};
    if (general) paths.push_back(ClosedChainPath::general);
    std::vector<std::vector<bench::LoopRepeat>> runs(2 * paths.size());  // [telemetry? 0 : 1][path]
    for (int r = 0; r < repeats; ++r)
      for (std::size_t p = 0; p < paths.size(); ++p) {
        set_closed_chain_path_preference(paths[p]);
        runs[p].push_back(bench::closed_loop_run(bundle, options, true, log));
        runs[paths.size() + p].push_back(bench::closed_loop_run(bundle, options, false, log));
      }
    set_closed_chain_path_preference(ClosedChainPath::planar);
    std::printf("| run | closed-chain model | real-time factor, loop thread CPU | all threads' CPU (one core) | wall%s | "
                "1 s simulated in |\n|---|---|---|---|---|---|\n", pin ? ", pinned to one core" : "");
    std::vector<double> process_factor(runs.size()), loop_factor(runs.size());  // medians, in the order of runs
    for (std::size_t i = 0; i < runs.size(); ++i) {
      std::vector<double> loop, process, wall;
      for (const bench::LoopRepeat& x : runs[i]) {
        loop.push_back(x.loop);
        process.push_back(x.process);
        wall.push_back(x.wall);
      }
      const bool logged = i < paths.size();
      std::printf("| %s | %s | %.0fx (%.0f-%.0f) | %.0fx | %.0fx | %.2f ms CPU |\n",
                  logged ? "telemetry, every message in an LCM log" : "no telemetry", bench::path_label(paths[i % paths.size()]),
                  median(loop), *std::min_element(loop.begin(), loop.end()), *std::max_element(loop.begin(), loop.end()),
                  median(process), median(wall), 1e3 / median(process));
      process_factor[i] = median(process);
      loop_factor[i] = median(loop);
    }
    const double logged_factor = process_factor[0], unlogged_factor = process_factor[paths.size()];
    std::printf("\nGoals on one core, all threads' CPU: >= %.0fx with every message logged: %.0fx, %s; >= %.0fx "
                "without telemetry: %.0fx, %s.",
                bench::kLoggedGoal, logged_factor, logged_factor >= bench::kLoggedGoal ? "met" : "NOT met", bench::kUnloggedGoal, unlogged_factor,
                unlogged_factor >= bench::kUnloggedGoal ? "met" : "NOT met");
    if (general)
      std::printf(" The planar path against the general one: %.2fx logged, %.2fx without telemetry.",
                  logged_factor / process_factor[1], unlogged_factor / process_factor[paths.size() + 1]);
    std::printf("\n");

    if (history > 0) {
      // A cycle's cost must not depend on the run's history (docs/floating-point.md): the path ends at
      // 10.05 s and the machine then holds; its decaying states reach the subnormal range unless flushed.
      std::printf("\n# A long run's first and last second (%s, %.0f s simulated, no telemetry; the path takes %.2f s, "
                  "then the machine holds)\n\n"
                  "| floating point | control step median, first / last second | its p99 | plant step median, first / "
                  "last second | its p99 | real-time factor, loop thread |\n|---|---|---|---|---|---|\n",
                  controller.c_str(), history, bundle.firmware.task.end_time() - bundle.firmware.task.start_time());
      const double long_factor = bench::print_history_row(bundle, options, history, app::FloatMode::flush_subnormals);
      bench::print_history_row(bundle, options, history, app::FloatMode::ieee);
      // Per simulated second, the long run in the loop's mode against this run's short ones without
      // telemetry (the same path and thread; the short ones' median).
      const double short_factor = loop_factor[paths.size()];
      std::printf("\nThe %.0f s run in the loop's mode: %.2f ms of loop-thread CPU per simulated second, against %.2f ms "
                  "for the %.1f s runs above without telemetry (%.2fx): %s.\n",
                  history, 1e3 / long_factor, 1e3 / short_factor, seconds, short_factor / long_factor,
                  long_factor >= short_factor ? "no slower, goal met" : "slower, goal NOT met");
    }

    bench::print_loop_floor(bundle, options, paths, repeats, seconds);

    if (split) {
      std::string why;
      const std::vector<std::string> args = {"--scene", scene_path, "--controller", controller, "--split-duration",
                                             std::to_string(split_duration), "--child"};
      const double split_cycles = std::round(split_duration / bundle.scene.cycle);
      char self[4096] = {};
      const ssize_t len = readlink("/proc/self/exe", self, sizeof self - 1);
      const std::string program = len > 0 ? self : argv[0];
      const auto counts =
          bench::callgrind_split(program, args, split_cycles, bench::loop_stages(), bench::loop_toggles(), why);
      std::printf("\n# Instructions per cycle by stage (callgrind, inclusive, %.0f cycles, %.1f s simulated)\n\n", split_cycles,
                  split_duration);
      if (counts.empty()) {
        // Asked for and not given: the run fails (the timing figures above stand).
        std::printf("not available: %s\n", why.c_str());
        std::fprintf(stderr, "excavator-loop-bench: --split: %s (Debian: apt-get install valgrind)\n", why.c_str());
        return 1;
      }
      std::printf("| stage | instructions per cycle | of the loop |\n|---|---|---|\n");
      for (const bench::StageCount& c : counts) {
        const std::string indent(static_cast<std::size_t>(2 * c.depth), ' ');
        if (c.per_cycle < 0) std::printf("| %s%s | (inlined) | |\n", indent.c_str(), c.stage.c_str());
        else std::printf("| %s%s | %.1fk | %.0f %% |\n", indent.c_str(), c.stage.c_str(), c.per_cycle * 1e-3,
                         100 * c.per_cycle / counts.front().per_cycle);
      }
      bench::print_bound_without_models(counts, bundle.scene.cycle, logged_factor, unlogged_factor);
      if (!bench::print_model_evaluations(program, scene_path, controller)) return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "excavator-loop-bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
