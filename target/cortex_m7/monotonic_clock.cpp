// hal::monotonic_now_ns on the emulated target: the instruction clock. Under QEMU's -icount shift=0
// the emulated clock advances one nanosecond per instruction, so the loop's timing counters
// (diagnostics/loop_counters.hpp), which read this clock, count instructions (40 a tick: docs/target.md).
#include "hal/clock.hpp"
#include "instruction_clock.hpp"

namespace exc::hal {

std::int64_t monotonic_now_ns() { return static_cast<std::int64_t>(target::InstructionClock::instructions()); }

}  // namespace exc::hal
