// The closed loop's measurements for excavator-loop-bench (bench/closed_loop_bench.hpp).
#include "closed_loop_bench.hpp"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

#include "app/firmware_node.hpp"
#include "callgrind_split.hpp"
#include "model/forward_dynamics.hpp"
#include "model_evaluations.hpp"
#include "sim_plant/plant.hpp"
#include "telemetry/lcm_output.hpp"

namespace exc::bench {

namespace {
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


double cpu_seconds(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// What the loop would run at if its model evaluations (plant and firmware) cost nothing: the
// instructions left, at the rate (instructions per second of all threads' CPU) this run's timing and
// the split give together (the table's all-threads medians, logged and not). An estimate (it assumes
// the model runs at the loop's average rate), printed because it says whether any cheaper model can
// reach a target factor on this machine.
void print_bound_without_models(const std::vector<StageCount>& counts, double period, double logged_factor,
                                double unlogged_factor) {
  auto find = [&](const char* prefix) {
    for (const StageCount& c : counts)
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
LoopRepeat closed_loop_run(const sim::SceneBundle& b, const sim::LockstepOptions& base, bool telemetry, const std::string& log) {
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
  return LoopRepeat{r.simulated_seconds / r.cpu_seconds, r.simulated_seconds / process, r.simulated_seconds / wall};
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

const char* path_label(ClosedChainPath path) {
  return path == ClosedChainPath::planar ? "planar (now)" : "general (before)";
}

// --child-model: each node's evaluation on `n` states, with each path, for callgrind to count apart.
bool evaluate_model_paths(const sim::SceneBundle& b, std::size_t n) {
  set_closed_chain_path_preference(ClosedChainPath::general);
  const Model plant_general = build_model(b.scene.machine), firmware_general = build_model(b.firmware.machine);
  set_closed_chain_path_preference(ClosedChainPath::planar);
  const Model plant_planar = build_model(b.scene.machine), firmware_planar = build_model(b.firmware.machine);
  const std::vector<ActiveState> states = random_valid_states(firmware_planar, n, 7);
  Workspace w1(firmware_planar), w2(firmware_general), w3(plant_planar), w4(plant_general);
  const double sum = firmware_evaluations_planar(firmware_planar, w1, states) +
                     firmware_evaluations_general(firmware_general, w2, states) +
                     plant_evaluations_planar(plant_planar, w3, states) +
                     plant_evaluations_general(plant_general, w4, states);
  return std::isfinite(sum);
}

// --split: one evaluation of the closed-chain model per node, each path, counted by callgrind in a
// child run of this program (--child-model). False when it could not be counted.
bool print_model_evaluations(const std::string& program, const std::string& scene, const std::string& controller) {
  constexpr int kStates = 2000;
  std::string why;
  const auto counts = callgrind_split(program,
                                             {"--scene", scene, "--controller", controller, "--child-model",
                                              std::to_string(kStates)},
                                             kStates, model_evaluation_stages(), model_evaluation_toggles(), why);
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

void print_loop_floor(const sim::SceneBundle& b, const sim::LockstepOptions& options,
                      const std::vector<ClosedChainPath>& paths, int repeats, double seconds) {
  // The floor: the loop's two model evaluations per cycle on this run's states, and the plant alone.
  const auto cycles = static_cast<std::size_t>(std::llround(seconds / b.scene.cycle));
  const Trace t = record(b, options, cycles);
  const std::size_t n = t.q_a.size();
  std::printf("\n# The floor (medians; the same run's %zu states)\n\n| per cycle | closed-chain model | us | bounds the loop "
              "at |\n|---|---|---|---|\n", n);
  long failed_evaluations = 0;
  Vec4 sink = Vec4::Zero();
  for (const ClosedChainPath path : paths) {
    set_closed_chain_path_preference(path);
    const Model plant_model = build_model(b.scene.machine), firmware_model = build_model(b.firmware.machine);
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
      plant::Plant p(b.scene);
      const double t0 = cpu_seconds(CLOCK_THREAD_CPUTIME_ID);
      for (std::size_t k = 0; k < n; ++k) p.step(t.commands[k]);
      replays.push_back(cpu_seconds(CLOCK_THREAD_CPUTIME_ID) - t0);
      sink += p.state().q_a;
    }
    const double replay_time = median(replays);
    const double period = b.scene.cycle;
    const char* label = path_label(path);
    std::printf("| plant: forward dynamics (update, M_a, h_a, solve) | %s | %.2f | %.0fx |\n", label, fd * 1e6, period / fd);
    std::printf("| firmware: the law's model (update, M_a, h_a) | %s | %.2f | %.0fx |\n", label, id * 1e6, period / id);
    std::printf("| both: the loop's floor on one core | %s | %.2f | %.0fx |\n", label, (fd + id) * 1e6, period / (fd + id));
    std::printf("| the plant alone, open loop with the run's commands (Plant::step) | %s | %.2f | %.0fx |\n", label,
                replay_time / static_cast<double>(n) * 1e6, period * static_cast<double>(n) / replay_time);
  }
  set_closed_chain_path_preference(ClosedChainPath::planar);
  if (failed_evaluations > 0 || !sink.allFinite())  // the floor timed evaluations that gave no number
    throw std::runtime_error("the floor's model evaluations failed (" + std::to_string(failed_evaluations) +
                             " refused, output " + (sink.allFinite() ? "finite" : "not finite") + ")");

}

}  // namespace exc::bench
