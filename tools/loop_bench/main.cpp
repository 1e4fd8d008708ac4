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
#include "callgrind_split.hpp"
#include "control/controller_kinds.hpp"
#include "harness/lockstep_run.hpp"
#include "model/forward_dynamics.hpp"
#include "output_file.hpp"
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
void print_history_row(const sim::SceneBundle& b, const sim::LockstepOptions& base, double seconds, app::FloatMode mode) {
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
  bool split = false, child = false, pin = true;
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
  app.add_flag("--child", child, "one run with telemetry and nothing printed (what --split profiles)")->group("");
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
    const double seconds = duration > 0 ? duration : bundle.scene.duration;
    std::printf("# Closed loop: %s, %s, %.1f s simulated, %d repeats (scene loading, effort-feasibility check "
                "included: %.2f s CPU, once)\n\n",
                bundle.name.c_str(), controller.c_str(), seconds, repeats, load_s);
    std::vector<Repeat> with, without;
    for (int r = 0; r < repeats; ++r) {  // alternating, so load that comes and goes meets both
      with.push_back(closed_loop(bundle, options, true, log));
      without.push_back(closed_loop(bundle, options, false, log));
    }
    std::printf("| run | real-time factor, loop thread CPU | all threads' CPU (one core) | wall%s | 1 s simulated in |\n"
                "|---|---|---|---|---|\n", pin ? ", pinned to one core" : "");
    double process_factor[2] = {};  // all threads' median: with telemetry, without
    for (const auto* set : {&with, &without}) {
      std::vector<double> loop, process, wall;
      for (const Repeat& x : *set) {
        loop.push_back(x.loop);
        process.push_back(x.process);
        wall.push_back(x.wall);
      }
      std::printf("| %s | %.0fx (%.0f-%.0f) | %.0fx | %.0fx | %.2f ms CPU |\n",
                  set == &with ? "telemetry, every message in an LCM log" : "no telemetry", median(loop),
                  *std::min_element(loop.begin(), loop.end()), *std::max_element(loop.begin(), loop.end()),
                  median(process), median(wall), 1e3 / median(process));
      process_factor[set == &with ? 0 : 1] = median(process);
    }

    if (history > 0) {
      // A cycle's cost must not depend on the run's history (docs/floating-point.md): the path ends at
      // 10.05 s and the machine then holds; its decaying states reach the subnormal range unless flushed.
      std::printf("\n# A long run's first and last second (%s, %.0f s simulated, no telemetry; the path takes %.2f s, "
                  "then the machine holds)\n\n"
                  "| floating point | control step median, first / last second | its p99 | plant step median, first / "
                  "last second | its p99 | real-time factor, loop thread |\n|---|---|---|---|---|---|\n",
                  controller.c_str(), history, bundle.firmware.task.end_time() - bundle.firmware.task.start_time());
      print_history_row(bundle, options, history, app::FloatMode::flush_subnormals);
      print_history_row(bundle, options, history, app::FloatMode::ieee);
    }

    // The floor: the loop's two model evaluations per cycle on this run's states, and the plant alone.
    const auto cycles = static_cast<std::size_t>(std::llround(seconds / bundle.scene.cycle));
    const Trace t = record(bundle, options, cycles);
    const std::size_t n = t.q_a.size();
    const Model plant_model = build_model(bundle.scene.machine), firmware_model = build_model(bundle.firmware.machine);
    Workspace pw(plant_model), fw(firmware_model);
    Vec4 sink = Vec4::Zero();
    long failed_evaluations = 0;
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
        failed_evaluations += !update_closed_chain(firmware_model, fw, t.q_fw[k], t.qd_fw[k]).ok();
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
    std::printf("\n# The floor (medians; the same run's %zu states)\n\n| per cycle | us | bounds the loop at |\n|---|---|---|\n", n);
    std::printf("| plant: forward dynamics (update, M_a, h_a, solve) | %.2f | %.0fx |\n", fd * 1e6, period / fd);
    std::printf("| firmware: the law's model (update, M_a, h_a) | %.2f | %.0fx |\n", id * 1e6, period / id);
    std::printf("| both: the loop's floor on one core | %.2f | %.0fx |\n", (fd + id) * 1e6, period / (fd + id));
    std::printf("| the plant alone, open loop with the run's commands (Plant::step) | %.2f | %.0fx |\n",
                replay_time / static_cast<double>(n) * 1e6, period * static_cast<double>(n) / replay_time);
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
      const auto counts = bench::callgrind_split(len > 0 ? self : argv[0], args, split_cycles, why);
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
      print_bound_without_models(counts, period, process_factor[0], process_factor[1]);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "excavator-loop-bench: %s\n", e.what());
    return 1;
  }
  return 0;
}
