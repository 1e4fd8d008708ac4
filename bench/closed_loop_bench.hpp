#pragma once
// excavator-loop-bench's measurements of the dig scene's closed loop against the
// speed goals set for it: a run's real-time factors with and without lossless telemetry, a long run's first and last
// second, the floor the loop's two model evaluations set on the same run's states, and the
// callgrind counts of one model evaluation per node and path. The program (tools/loop_bench) parses
// its flags, orders the runs and prints the tables' heads.
#include <time.h>

#include <cstddef>
#include <string>
#include <vector>

#include "app/float_environment.hpp"
#include "bench_common.hpp"
#include "callgrind_split.hpp"
#include "harness/lockstep_run.hpp"
#include "model/model.hpp"

namespace exc::bench {

// The speed goals for the dig scene's closed loop, all threads' CPU on one core, and for one
// evaluation of the closed-chain model (half of the 14.1k instructions it took before).
constexpr double kLoggedGoal = 300, kUnloggedGoal = 400, kModelEvaluationGoal = 7.1e3;

// Seconds of CPU of `clock` (CLOCK_THREAD_CPUTIME_ID, CLOCK_PROCESS_CPUTIME_ID). median() is bench_common's.
double cpu_seconds(clockid_t clock);

struct LoopRepeat {
  double loop = 0, process = 0, wall = 0;  // real-time factors: loop thread CPU, all threads' CPU, wall
};

// One closed-loop run; with telemetry every message goes into an LCM log file at `log` (blocking
// publisher), removed afterwards. Throws when the run fails or telemetry lost a message.
LoopRepeat closed_loop_run(const sim::SceneBundle& b, const sim::LockstepOptions& base, bool telemetry,
                           const std::string& log);

// A long run without telemetry in one floating-point mode: its first and last second side by side
// as a table row. Returns its real-time factor (loop thread).
double print_history_row(const sim::SceneBundle& b, const sim::LockstepOptions& base, double seconds, app::FloatMode mode);

// "planar (now)" or "general (before)".
const char* path_label(ClosedChainPath path);

// The floor: the plant's forward dynamics and the firmware's law's model per cycle on one run's
// states, each path in `paths`, and the plant alone replaying the run's commands; medians of
// `repeats`, printed as a table. Throws when an evaluation failed (the figures would mean nothing).
void print_loop_floor(const sim::SceneBundle& b, const sim::LockstepOptions& options,
                      const std::vector<ClosedChainPath>& paths, int repeats, double seconds);

// What the loop would run at if its model evaluations cost nothing, from the split's counts and this
// run's factors (an estimate, printed as such).
void print_bound_without_models(const std::vector<StageCount>& counts, double period, double logged_factor,
                                double unlogged_factor);

// --child-model: each node's evaluation on `n` states, with each path, for callgrind to count apart.
bool evaluate_model_paths(const sim::SceneBundle& b, std::size_t n);

// --split: one evaluation of the closed-chain model per node, each path, counted by callgrind in a
// child run of `program` (--child-model). False when it could not be counted.
bool print_model_evaluations(const std::string& program, const std::string& scene, const std::string& controller);

}  // namespace exc::bench
