// excavator-loop-bench: the closed loop's real-time factor (issue 17, item 3). The dig scene's whole
// in-process loop (firmware, CAN codec and in-memory bus, plant, lossless telemetry into an LCM log)
// through the harness every tool uses, medians over repeats; the floor the loop's two model
// evaluations set (the plant's forward dynamics, the firmware's M_a and h_a) on the same run's
// states; and, with --split, the per-stage instruction split of one cycle (callgrind). Build Release.
#include <sched.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "model/scene_common.hpp"
#include "option_checks.hpp"

#include "app/float_environment.hpp"
#include "app/firmware_node.hpp"
#include "bench/callgrind_split.hpp"
#include "control/controller_kinds.hpp"
#include "harness/lockstep_run.hpp"
#include "model/forward_dynamics.hpp"
#include "bench/model_evaluations.hpp"
#include "output_files/output_file.hpp"
#include "sim_plant/plant.hpp"
#include "telemetry/lcm_output.hpp"

using namespace exc;

namespace {

double cpu_seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

struct Repeat {
  double loop = 0, process = 0, wall = 0;  // real-time factors: loop thread CPU, all threads' CPU, wall
};

// What the loop would run at if its model evaluations (plant and firmware) cost nothing: the
// instructions left, at the rate (instructions per second of all threads' CPU) this run's timing and
// the split give together (the table's all-threads medians, logged and not). An estimate (it assumes
// the model runs at the loop's average rate), printed because it says whether any cheaper model can
// reach a target factor on this machine.
void print_bound_without_models(const std::vector<bench::StageCount>& counts, double period, double logged_factor,
                                double unlogged_factor) {
  auto find = [&](const char* prefix) {
    for (const bench::StageCount& c : counts)
      if (c.stage.rfind(prefix, 0) == 0) return c.per_cycle;
    return -1.0;
  };
  const double loop = counts.front().per_cycle, models = find("across the nodes: the model evaluations"),
               thread = find("telemetry thread"), plant_encode = find("telemetry encode (PlantNode"),
               firmware_encode = find("telemetry encode (publish_cycle");
  if (models <= 0 || thread < 0 || plant_encode < 0 || firmware_encode < 0) {
    std::printf("\n(no estimate without the model evaluations: a stage was inlined)\n");
    return;
  }
  const double logged = loop + thread, unlogged = loop - plant_encode - firmware_encode;
  const double rate_logged = logged * logged_factor / period;  // instructions per CPU second
  const double rate_unlogged = unlogged * unlogged_factor / period;
  std::printf("\nThe model evaluations are %.0f %% of a logged cycle's instructions (%.1fk of %.1fk with the "
              "telemetry thread). At this run's rates (%.1f and %.1f instructions per ns of CPU, logged and not), "
              "the loop without them would run at about %.0fx with every telemetry message logged and %.0fx with "
              "none.\n",
              100 * models / logged, models * 1e-3, logged * 1e-3, rate_logged * 1e-9, rate_unlogged * 1e-9,
              period * rate_logged / (logged - models), period * rate_unlogged / (unlogged - models));
}

// One closed-loop run; with telemetry every message goes into an LCM log file (blocking publisher).
Repeat closed_loop(const sim::SceneBundle& b, const sim::LockstepOptions& base, bool telemetry, const std::string& log) {
  sim::LockstepOptions o = base;
  if (telemetry) {
    std::string error;
    o.telemetry = telemetry::LcmOutput::open("file://" + log + "?mode=w", &error);
    if (!o.telemetry) throw std::runtime_error(error);
  }
  const double p0 = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID);
  const auto w0 = std::chrono::steady_clock::now();
  const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
  o.telemetry.reset();  // closes the log: its last writes are counted
  const double process = cpu_seconds(CLOCK_PROCESS_CPUTIME_ID) - p0;
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count();
  if (telemetry) std::remove(log.c_str());
  if (!r.ok) throw std::runtime_error("the run failed: " + r.failure);
  if (telemetry && (r.telemetry_dropped != 0 || r.telemetry_published != r.telemetry_enqueued))
    throw std::runtime_error("telemetry lost messages");
  return Repeat{r.simulated_seconds / r.cpu_seconds, r.simulated_seconds / process, r.simulated_seconds / wall};
}

// What one closed-loop run saw, cycle by cycle: the plant's state and the commands it stepped with,
// the firmware's measured state.
struct Trace {
  std::vector<plant::ActuatorCommand> commands;
  std::vector<Vec4> q_a, qd_a, effort, q_fw, qd_fw;
};

Trace record(const sim::SceneBundle& b, sim::LockstepOptions o, std::size_t cycles) {
  Trace t;
  for (auto* v : {&t.q_a, &t.qd_a, &t.effort, &t.q_fw, &t.qd_fw}) v->reserve(cycles + 1);
  t.commands.reserve(cycles + 1);
  plant::ActuatorCommand centred;  // the plant's first step, before any command: valves centred
  centred.mode = plant::ActuatorCommand::valve;
  t.commands.push_back(centred);
  o.observer = [&t](std::int64_t, const plant::Plant& p, const app::FirmwareNode& n) {
    const plant::PlantState& s = p.state();
    t.q_a.push_back(s.q_a);
    t.qd_a.push_back(s.qd_a);
    t.effort.push_back(s.effort);
    const hal::SensorState& m = n.sensors();
    t.q_fw.emplace_back(m.position[0], m.position[1], m.position[2], m.position[3]);
    t.qd_fw.emplace_back(m.velocity[0], m.velocity[1], m.velocity[2], m.velocity[3]);
    const hal::CommandState& c = n.last_command();  // what the plant steps with at the next SYNC
    plant::ActuatorCommand a;
    a.mode = c.mode == hal::CommandMode::pilot   ? plant::ActuatorCommand::pilot
             : c.mode == hal::CommandMode::valve ? plant::ActuatorCommand::valve
                                                 : plant::ActuatorCommand::effort;
    for (int j = 0; j < 4; ++j) {
      a.value[j] = c.value[j];
      a.pilot_a[j] = c.pilot_a[j];
      a.pilot_b[j] = c.pilot_b[j];
    }
    t.commands.push_back(a);
  };
  sim::run_lockstep(b.scene, b.firmware, o);
  return t;
}

// A long run without telemetry in one floating-point mode: its first and last second side by side.
// Returns its real-time factor (loop thread).
double print_history_row(const sim::SceneBundle& b, const sim::LockstepOptions& base, double seconds, app::FloatMode mode) {
  sim::LockstepOptions o = base;
  o.duration = seconds;
  o.float_mode = mode;
  const sim::RunRecord r = sim::run_lockstep(b.scene, b.firmware, o);
  if (!r.ok) throw std::runtime_error("the " + std::to_string(seconds) + " s run failed: " + r.failure);
  const sim::TimingWindow &first = r.first_second, &last = r.last_second;
  std::printf("| %s | %.2f / %.2f us (%.2fx) | %.2f / %.2f us | %.2f / %.2f us (%.2fx) | %.2f / %.2f us | %.0fx |\n",
              mode == app::FloatMode::flush_subnormals ? "flush-to-zero (the loop's mode)" : "IEEE gradual underflow",
              first.control_step.median_us, last.control_step.median_us,
              last.control_step.median_us / first.control_step.median_us, first.control_step.p99_us,
              last.control_step.p99_us, first.plant_step.median_us, last.plant_step.median_us,
              last.plant_step.median_us / first.plant_step.median_us, first.plant_step.p99_us, last.plant_step.p99_us,
              r.simulated_seconds / r.cpu_seconds);
  return r.simulated_seconds / r.cpu_seconds;
}

// Issue 34's goals for the dig scene's closed loop, all threads' CPU on one core, and for one
// evaluation of the closed-chain model (half of the 14.1k instructions it took before).
constexpr double kLoggedGoal = 300, kUnloggedGoal = 400, kModelEvaluationGoal = 7.1e3;

const char* path_label(ClosedChainPath path) {
  return path == ClosedChainPath::planar ? "planar (now)" : "general (before)";
}

// --child-model: each node's evaluation on `n` states, with each path, for callgrind to count apart.
bool evaluate_models(const sim::SceneBundle& b, std::size_t n) {
  set_closed_chain_path_preference(ClosedChainPath::general);
  const Model plant_general = build_model(b.scene.machine), firmware_general = build_model(b.firmware.machine);
  set_closed_chain_path_preference(ClosedChainPath::planar);
  const Model plant_planar = build_model(b.scene.machine), firmware_planar = build_model(b.firmware.machine);
  const std::vector<bench::ActiveState> states = bench::random_valid_states(firmware_planar, n, 7);
  Workspace w1(firmware_planar), w2(firmware_general), w3(plant_planar), w4(plant_general);
  const double sum = bench::firmware_evaluations_planar(firmware_planar, w1, states) +
                     bench::firmware_evaluations_general(firmware_general, w2, states) +
                     bench::plant_evaluations_planar(plant_planar, w3, states) +
                     bench::plant_evaluations_general(plant_general, w4, states);
  return std::isfinite(sum);
}

// --split: one evaluation of the closed-chain model per node, each path, counted by callgrind in a
// child run of this program (--child-model). False when it could not be counted.
bool print_model_evaluations(const std::string& program, const std::string& scene, const std::string& controller) {
  constexpr int kStates = 2000;
  std::string why;
  const auto counts = bench::callgrind_split(program,
                                             {"--scene", scene, "--controller", controller, "--child-model",
                                              std::to_string(kStates)},
                                             kStates, bench::model_evaluation_stages(), bench::model_evaluation_toggles(), why);
  std::printf("\n# One evaluation of the closed-chain model (update_closed_chain, mass_matrix, bias_forces): "
              "instructions (callgrind), the mean over %d random valid states\n\n", kStates);
  if (counts.size() != 4 || counts[0].per_cycle < 0 || counts[2].per_cycle < 0) {
    std::printf("not available: %s\n", why.empty() ? "an evaluation was not in the profile" : why.c_str());
    std::fprintf(stderr, "excavator-loop-bench: --split: the model evaluations were not counted: %s\n", why.c_str());
    return false;
  }
  std::printf("| node | planar path (now) | general path (before) | now / before |\n|---|---|---|---|\n");
  const char* nodes[2] = {"the firmware's law (passive angles skipped)", "the plant's integrator (the 8 passive angles computed)"};
  double largest = 0;
  for (int k = 0; k < 2; ++k) {
    const double now = counts[2 * k].per_cycle, before = counts[2 * k + 1].per_cycle;
    largest = std::max(largest, now);
    std::printf("| %s | %.2fk | %.2fk | %.2f |\n", nodes[k], now * 1e-3, before * 1e-3, now / before);
  }
  std::printf("\nGoal: one evaluation in at most %.1fk instructions: %s (the larger, %.2fk).\n", kModelEvaluationGoal * 1e-3,
              largest <= kModelEvaluationGoal ? "met" : "NOT met", largest * 1e-3);
  return true;
}

// Thread CPU seconds of `body`, the median of `repeats` runs.
template <class Body>
double timed(int repeats, Body&& body) {
  std::vector<double> s;
  for (int r = 0; r < repeats; ++r) {
    const double t0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    body();
    s.push_back(cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - t0);
  }
  return median(s);
}

}  // namespace

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

  const auto kind = control::kControllerKinds.named(controller);
  if (!kind) {
    std::fprintf(stderr, "excavator-loop-bench: unknown controller '%s'\n", controller.c_str());
    return 2;
  }
  if (pin) {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(std::max(0, sched_getcpu()), &one);
    sched_setaffinity(0, sizeof one, &one);  // every thread started from here on shares the core
  }
  try {
    const double load0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
    const sim::SceneBundle bundle = sim::load_scene_bundle(scene_path);
    const double load_s = cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - load0;
    sim::LockstepOptions options;
    options.controller = *kind;
    options.duration = duration;
    const std::string log = "/tmp/loop-bench-" + std::to_string(getpid()) + ".lcm";
    if (child) {
      options.duration = split_duration;
      closed_loop(bundle, options, true, log);
      return 0;
    }
    if (child_model > 0) return evaluate_models(bundle, static_cast<std::size_t>(child_model)) ? 0 : 1;
    const double seconds = duration > 0 ? duration : bundle.scene.duration;
    std::printf("# Closed loop: %s, %s, %.1f s simulated, %d repeats (scene loading, effort-feasibility check "
                "included: %.2f s CPU, once)\n\n",
                bundle.name.c_str(), controller.c_str(), seconds, repeats, load_s);
    // Every figure with the planar path (now) and, unless --no-general, the general one (before), the
    // runs alternating so that load that comes and goes meets all of them.
    std::vector<ClosedChainPath> paths = {ClosedChainPath::planar};
    if (general) paths.push_back(ClosedChainPath::general);
    std::vector<std::vector<Repeat>> runs(2 * paths.size());  // [telemetry? 0 : 1][path]
    for (int r = 0; r < repeats; ++r)
      for (std::size_t p = 0; p < paths.size(); ++p) {
        set_closed_chain_path_preference(paths[p]);
        runs[p].push_back(closed_loop(bundle, options, true, log));
        runs[paths.size() + p].push_back(closed_loop(bundle, options, false, log));
      }
    set_closed_chain_path_preference(ClosedChainPath::planar);
    std::printf("| run | closed-chain model | real-time factor, loop thread CPU | all threads' CPU (one core) | wall%s | "
                "1 s simulated in |\n|---|---|---|---|---|---|\n", pin ? ", pinned to one core" : "");
    std::vector<double> process_factor(runs.size()), loop_factor(runs.size());  // medians, in the order of runs
    for (std::size_t i = 0; i < runs.size(); ++i) {
      std::vector<double> loop, process, wall;
      for (const Repeat& x : runs[i]) {
        loop.push_back(x.loop);
        process.push_back(x.process);
        wall.push_back(x.wall);
      }
      const bool logged = i < paths.size();
      std::printf("| %s | %s | %.0fx (%.0f-%.0f) | %.0fx | %.0fx | %.2f ms CPU |\n",
                  logged ? "telemetry, every message in an LCM log" : "no telemetry", path_label(paths[i % paths.size()]),
                  median(loop), *std::min_element(loop.begin(), loop.end()), *std::max_element(loop.begin(), loop.end()),
                  median(process), median(wall), 1e3 / median(process));
      process_factor[i] = median(process);
      loop_factor[i] = median(loop);
    }
    const double logged_factor = process_factor[0], unlogged_factor = process_factor[paths.size()];
    std::printf("\nGoals on one core, all threads' CPU: >= %.0fx with every message logged: %.0fx, %s; >= %.0fx "
                "without telemetry: %.0fx, %s.",
                kLoggedGoal, logged_factor, logged_factor >= kLoggedGoal ? "met" : "NOT met", kUnloggedGoal, unlogged_factor,
                unlogged_factor >= kUnloggedGoal ? "met" : "NOT met");
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
      const double long_factor = print_history_row(bundle, options, history, app::FloatMode::flush_subnormals);
      print_history_row(bundle, options, history, app::FloatMode::ieee);
      // Per simulated second, the long run in the loop's mode against this run's short ones without
      // telemetry (the same path and thread; the short ones' median).
      const double short_factor = loop_factor[paths.size()];
      std::printf("\nThe %.0f s run in the loop's mode: %.2f ms of loop-thread CPU per simulated second, against %.2f ms "
                  "for the %.1f s runs above without telemetry (%.2fx): %s.\n",
                  history, 1e3 / long_factor, 1e3 / short_factor, seconds, short_factor / long_factor,
                  long_factor >= short_factor ? "no slower, goal met" : "slower, goal NOT met");
    }

    // The floor: the loop's two model evaluations per cycle on this run's states, and the plant alone.
    const auto cycles = static_cast<std::size_t>(std::llround(seconds / bundle.scene.cycle));
    const Trace t = record(bundle, options, cycles);
    const std::size_t n = t.q_a.size();
    std::printf("\n# The floor (medians; the same run's %zu states)\n\n| per cycle | closed-chain model | us | bounds the loop "
                "at |\n|---|---|---|---|\n", n);
    long failed_evaluations = 0;
    Vec4 sink = Vec4::Zero();
    for (const ClosedChainPath path : paths) {
      set_closed_chain_path_preference(path);
      const Model plant_model = build_model(bundle.scene.machine), firmware_model = build_model(bundle.firmware.machine);
      Workspace pw(plant_model), fw(firmware_model);
      const double fd = timed(repeats, [&] {
        Vec4 qdd;
        for (std::size_t k = 0; k < n; ++k) {
          failed_evaluations += !forward_dynamics(plant_model, pw, t.q_a[k], t.qd_a[k], t.effort[k], TipLoad{}, qdd).ok();
          sink += qdd;
        }
      }) / static_cast<double>(n);
      const double id = timed(repeats, [&] {
        Mat4 M;
        Vec4 h;
        for (std::size_t k = 0; k < n; ++k) {
          failed_evaluations += !update_closed_chain(firmware_model, fw, t.q_fw[k], t.qd_fw[k], PassiveAngles::skipped).ok();
          mass_matrix(firmware_model, fw, M);
          bias_forces(firmware_model, fw, h);
          sink += h + M.col(0);
        }
      }) / static_cast<double>(n);
      std::vector<double> replays;
      for (int r = 0; r < repeats; ++r) {
        plant::Plant p(bundle.scene);
        const double t0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
        for (std::size_t k = 0; k < n; ++k) p.step(t.commands[k]);
        replays.push_back(cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - t0);
        sink += p.state().q_a;
      }
      const double replay_time = median(replays);
      const double period = bundle.scene.cycle;
      const char* label = path_label(path);
      std::printf("| plant: forward dynamics (update, M_a, h_a, solve) | %s | %.2f | %.0fx |\n", label, fd * 1e6, period / fd);
      std::printf("| firmware: the law's model (update, M_a, h_a) | %s | %.2f | %.0fx |\n", label, id * 1e6, period / id);
      std::printf("| both: the loop's floor on one core | %s | %.2f | %.0fx |\n", label, (fd + id) * 1e6, period / (fd + id));
      std::printf("| the plant alone, open loop with the run's commands (Plant::step) | %s | %.2f | %.0fx |\n", label,
                  replay_time / static_cast<double>(n) * 1e6, period * static_cast<double>(n) / replay_time);
    }
    set_closed_chain_path_preference(ClosedChainPath::planar);
    if (failed_evaluations > 0 || !sink.allFinite()) {
      // The floor timed evaluations that failed or gave no number: its figures mean nothing.
      std::fprintf(stderr, "excavator-loop-bench: the floor's model evaluations failed (%ld refused, output %s)\n",
                   failed_evaluations, sink.allFinite() ? "finite" : "not finite");
      return 1;
    }

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
      print_bound_without_models(counts, bundle.scene.cycle, logged_factor, unlogged_factor);
      if (!print_model_evaluations(program, scene_path, controller)) return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "excavator-loop-bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
