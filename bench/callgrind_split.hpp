#pragma once
// The closed loop's per-stage instruction split: this program runs itself once more under valgrind's
// callgrind (one short run of the same scene), then reads callgrind_annotate's inclusive counts of the
// loop's functions and divides them by the cycles run. Instruction counts are steadier than times on
// a shared machine; the functions named here are the stages of one cycle (firmware_node.cpp,
// plant_node.cpp, hal/).
#include <string>
#include <vector>

namespace exc::bench {

struct StageCount {
  std::string stage;      // the stage as the README names it
  int depth = 0;          // 0: the loop or a cross-cutting figure, 1: a node, 2: a part of it, ...
  double per_cycle = -1;  // instructions per cycle; -1: no such function in the profile (inlined)
};

// A stage: the functions whose inclusive counts it sums (substrings of callgrind_annotate's
// "file:function" column; a template's instantiations all match).
struct Stage {
  const char* label;
  int depth;
  std::vector<const char*> functions;
};

// The stages of one cycle of the closed loop (counted inside run_lockstep and the telemetry thread).
const std::vector<Stage>& loop_stages();
const std::vector<std::string>& loop_toggles();
// One evaluation of the closed-chain model per node and path (model_evaluations.hpp).
const std::vector<Stage>& model_evaluation_stages();
const std::vector<std::string>& model_evaluation_toggles();

// Runs `program` with `args` (a child run of `cycles` cycles, or evaluations) under callgrind,
// collecting only inside the functions `toggles` name, and sums `stages` per cycle. Empty, with the
// reason in `why`, when valgrind or callgrind_annotate is missing or the child run failed.
std::vector<StageCount> callgrind_split(const std::string& program, const std::vector<std::string>& args, double cycles,
                                        const std::vector<Stage>& stages, const std::vector<std::string>& toggles,
                                        std::string& why);

}  // namespace exc::bench
