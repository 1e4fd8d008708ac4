// exc-hold-instruction-windows: the dig scene with one law for --duration simulated seconds, with
// callgrind's client requests around two windows of --window cycles: one early in the hold (from
// --early s; the path ends at 10.05 s) and the run's last. Each window is counted on its own and
// dumped ("early", "late"). Run it under valgrind --tool=callgrind --instr-atstart=no (the cycles
// outside the windows then run uninstrumented); natively the requests do nothing. Used by
// test_hold_instructions.cpp. Exit 1 when the run fails or never finishes its path.
#include <valgrind/callgrind.h>

#include <cmath>
#include <cstdio>
#include <string>

#include <CLI/CLI.hpp>

#include "control/controller_registry.hpp"
#include "harness/lockstep_run.hpp"

using namespace exc;

int main(int argc, char** argv) {
  CLI::App app{"The dig scene's closed loop with two callgrind windows, early in the hold and at the run's end "
               "(run under valgrind --tool=callgrind --instr-atstart=no)",
               "exc-hold-instruction-windows"};
  std::string controller = "adaptive";
  double duration = 60, early = 11;
  int window = 1000;
  app.add_option("--controller", controller, control::controller_registry().names())
      ->check(CLI::IsMember(control::controller_registry().name_list()));
  app.add_option("--duration", duration, "simulated seconds (default 60)")->check(CLI::Range(12.0, 3600.0));
  app.add_option("--early", early, "start of the early window, s (default 11: the path ends at 10.05 s)")
      ->check(CLI::Range(10.1, 3600.0));
  app.add_option("--window", window, "cycles per window (default 1000)")->check(CLI::Range(10, 100000));
  CLI11_PARSE(app, argc, argv);

  const sim::SceneBundle b = sim::load_scene_bundle(std::string(EXC_SOURCE_DIR) + "/scenes/dig.yaml");
  const auto cycles = static_cast<std::int64_t>(std::llround(duration / b.scene.cycle));
  const auto early_begin = static_cast<std::int64_t>(std::llround(early / b.scene.cycle));
  const std::int64_t late_begin = cycles - window;
  if (early_begin + window > late_begin) {
    std::fprintf(stderr, "exc-hold-instruction-windows: the windows overlap (early %g s, %d cycles, duration %g s)\n", early,
                 window, duration);
    return 2;
  }
  sim::LockstepOptions o;
  o.controller = controller;
  o.duration = duration;
  // The observer runs after cycle k: a window [begin, begin + window) starts after cycle begin - 1.
  o.observer = [&](std::int64_t k, const plant::Plant&, const app::FirmwareNode&) {
    if (k + 1 == early_begin || k + 1 == late_begin) {
      CALLGRIND_START_INSTRUMENTATION;
      CALLGRIND_ZERO_STATS;
    } else if (k + 1 == early_begin + window) {
      CALLGRIND_DUMP_STATS_AT("early");
      CALLGRIND_STOP_INSTRUMENTATION;
    } else if (k + 1 == late_begin + window) {
      CALLGRIND_DUMP_STATS_AT("late");
      CALLGRIND_STOP_INSTRUMENTATION;
    }
  };
  const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
  std::printf("exc-hold-instruction-windows: %s, %.3f s simulated, path finished %s at %.3f s, windows of %d cycles "
              "from %.3f s and %.3f s\n",
              controller.c_str(), r.simulated_seconds, r.task_finished ? "yes" : "no", r.task_finish_time, window,
              static_cast<double>(early_begin) * b.scene.cycle, static_cast<double>(late_begin) * b.scene.cycle);
  if (!r.ok || !r.task_finished || early_begin * b.scene.cycle < r.task_finish_time) {
    std::fprintf(stderr, "exc-hold-instruction-windows: the run did not hold from before the early window: %s\n",
                 r.failure.c_str());
    return 1;
  }
  return 0;
}
