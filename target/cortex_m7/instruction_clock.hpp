#pragma once
// A monotonic 64-bit count of the instructions the emulated Cortex-M7 has executed, from SysTick.
//
// QEMU with -icount shift=0 advances its virtual clock by 1 ns per instruction, and the mps2-an500's
// SysTick, on the 25 MHz processor clock, ticks once per 40 ns: once per 40 instructions. SysTick is a
// 24-bit down-counter; with the full reload it wraps every 2^24 ticks (671 million instructions) and
// its interrupt counts the wraps, which extend it to 64 bits. Resolution: 40 instructions (a reading
// is a multiple of 40; a difference of two is within 40 of the instructions between them, plus the
// reading's own few). Deterministic: the same image with the same input reads the same counts.
// Under a time-based clock (no -icount, or real hardware) the same counter counts processor clock
// ticks: the instruction figures then mean nothing.
#include <cstdint>

namespace exc::target {

class InstructionClock {
 public:
  static constexpr std::uint32_t kInstructionsPerTick = 40;

  static constexpr std::uint32_t kFullReload = 0x00FFFFFF;

  // Starts SysTick on the processor clock with its wrap interrupt, counting from 0. The start-up code
  // calls it (full reload) before the static constructors. A smaller reload wraps sooner: for testing
  // the extension across many wraps (1 to 2^24 - 1; the period is reload + 1 ticks).
  static void start(std::uint32_t reload = kFullReload);
  // Whether start() has run (the counter counts).
  static bool running();
  // SysTick ticks since start(), 64 bits (never wraps in practice: 2^64 ticks). Safe to call with
  // interrupts masked (a wrap pending is counted) but not from a handler of higher priority than
  // SysTick's that runs for longer than a period.
  static std::uint64_t ticks();
  // Instructions since start(): ticks() * 40, valid under QEMU's -icount shift=0.
  static std::uint64_t instructions() { return ticks() * kInstructionsPerTick; }
};

}  // namespace exc::target

// The SysTick exception's handler (the vector table names it).
extern "C" void exc_systick_handler();
