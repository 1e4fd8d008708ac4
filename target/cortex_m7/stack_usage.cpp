#include "stack_usage.hpp"

// The linker script's stack: [__stack_limit, __stack_top), growing down from the top.
extern "C" std::uint32_t __stack_limit[];
extern "C" std::uint32_t __stack_top[];

namespace exc::target {

std::size_t stack_size_bytes() {
  return static_cast<std::size_t>(reinterpret_cast<char*>(__stack_top) - reinterpret_cast<char*>(__stack_limit));
}

std::size_t stack_high_water_bytes() {
  const volatile std::uint32_t* word = __stack_limit;
  while (word < __stack_top && *word == kStackPaint) ++word;
  return static_cast<std::size_t>(reinterpret_cast<const volatile char*>(__stack_top) -
                                  reinterpret_cast<const volatile char*>(word));
}

}  // namespace exc::target
