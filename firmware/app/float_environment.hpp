#pragma once
// The floating-point environment of every thread that runs the firmware's loop or the plant's step
// (docs/floating-point.md). While the machine holds, decaying states (the velocity filters, the
// spool lead, the plant's spool lag) fall into the subnormal range and stay there; x86-64 handles a
// subnormal operand or result in microcode, many times slower, so without this a cycle's cost grew
// with the time the machine had stood still (the control step had run 4-5x slower after a minute).
// The loop's mode flushes them: a result below the smallest normal number (2.2e-308) becomes zero
// and a subnormal operand is read as zero. x86-64: MXCSR FTZ (bit 15) and DAZ (bit 6); AArch64:
// FPCR.FZ (bit 24), which does both. The mode belongs to a thread; Linux copies it into the threads
// that thread starts afterwards (the telemetry thread), and the test of this header checks that.
#include <cstdint>
#include <cstring>

#include "settings/enum_table.hpp"

namespace exc::app {

enum class FloatMode : std::uint8_t {
  flush_subnormals,  // FTZ + DAZ (AArch64 FZ): the loop's mode
  ieee,              // gradual underflow, the processor's default: for comparison runs only
};
inline constexpr settings::EnumTable<FloatMode, 2> kFloatModes{{{
    {FloatMode::flush_subnormals, "flush", "subnormal results and operands flushed to zero (FTZ and DAZ): the loop's mode"},
    {FloatMode::ieee, "ieee", "gradual underflow, the processor's default: a long hold's cycles get slower"},
}}};

// The calling thread's floating-point control word, as set_loop_float_mode found it.
struct FloatControl {
  std::uint64_t bits = 0;
};

// Puts the calling thread into `mode` and returns the control word it replaced (for
// restore_float_control). Called first thing by every thread that runs the loop or the plant: the
// real-time runner (excavator-firmware), the plant process (excavator-plant), the lockstep harness
// (run_lockstep, for the run) and the benches. On a processor other than x86-64 and AArch64 it does
// nothing and float_mode_of_thread() says ieee.
FloatControl set_loop_float_mode(FloatMode mode = FloatMode::flush_subnormals);
void restore_float_control(FloatControl saved);

// The calling thread's mode as its processor holds it: flush_subnormals only with both flags set.
FloatMode float_mode_of_thread();

// Reads and clears the calling thread's sticky underflow flag (x86-64 MXCSR UE, AArch64 FPSR.UFC): set
// by a result that was tiny, flushed to zero in the loop's mode. Counts how often the mode acts.
bool take_underflow_flag();

// The loop's mode for a scope (a run of the lockstep harness), then the caller's mode again.
class LoopFloatModeScope {
 public:
  explicit LoopFloatModeScope(FloatMode mode = FloatMode::flush_subnormals) : saved_(set_loop_float_mode(mode)) {}
  ~LoopFloatModeScope() { restore_float_control(saved_); }
  LoopFloatModeScope(const LoopFloatModeScope&) = delete;
  LoopFloatModeScope& operator=(const LoopFloatModeScope&) = delete;

 private:
  FloatControl saved_;
};


}  // namespace exc::app
