#pragma once
// The main stack's high-water mark. The reset handler paints the whole stack with kStackPaint before
// anything runs on it; the deepest word ever written is the lowest one no longer painted. Scanning
// is O(stack size): read it at the end of a run or between cycles, not inside the timed stages.
// A frame that reserved words without writing them, or wrote the paint itself, reads as shallower.
#include <cstddef>
#include <cstdint>

namespace exc::target {

inline constexpr std::uint32_t kStackPaint = 0x5A5AA5A5;  // reset_handler.S's STACK_PAINT

// The stack's size (the linker script's __stack_size).
std::size_t stack_size_bytes();
// Bytes from the stack's top down to its deepest written word.
std::size_t stack_high_water_bytes();

}  // namespace exc::target
