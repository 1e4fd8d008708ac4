#pragma once
// What a run on the emulated Cortex-M7 measures of the firmware's image (docs/target.md): its
// instructions per cycle and per stage (exact, from each cycle's counts: median, 99th percentile,
// max), its painted stack's high-water mark, its flash and RAM from the ELF, and the allocator calls
// it made after start-up.
#include <array>
#include <cstdint>
#include <string>

#include "app/pil_records.hpp"

namespace exc::sim {

struct InstructionFigures {
  std::uint64_t median = 0, p99 = 0, max = 0;
  std::uint64_t cycles = 0;  // samples (the cycles the stage ran in)
};

struct TargetFigures {
  std::string name = "cortex-m7";
  std::string image;  // the ELF
  std::array<InstructionFigures, app::kTargetStages> stages{};  // by app::kTargetStageNames; the last is the cycle
  std::uint64_t worst_cycle = 0;  // the cycle (count from 1) of the most instructions
  std::uint64_t stack_bytes = 0;
  std::uint64_t stack_size_bytes = 0;
  std::uint64_t flash_bytes = 0, ram_bytes = 0;
  std::uint64_t heap_calls_after_start_up = 0;
  std::uint64_t start_up_instructions = 0;
  const InstructionFigures& per_cycle() const { return stages[app::kTargetStages - 1]; }
};

}  // namespace exc::sim
