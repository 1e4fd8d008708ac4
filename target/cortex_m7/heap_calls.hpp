#pragma once
// Counts every call into newlib's allocator: malloc, calloc, realloc, free and memalign, whoever makes
// them. newlib's own code (stdio's buffers, dtoa's big numbers, aligned_alloc) calls the reentrant
// entry points _malloc_r & co. directly, and malloc() is a call to _malloc_r, so the image is linked
// with -Wl,--wrap for those five (target/cortex_m7/CMakeLists.txt) and every call lands here.
// operator new and delete (libstdc++) go through malloc and free. A call the allocator makes into
// itself (realloc into malloc and free, calloc into malloc) counts once, as the outer call.
//
// mark_start_up_over() draws the line the firmware is held to: after it, the cycle makes no heap call.
// Interrupt handlers must not allocate (the nesting guard is not interrupt-safe, and they do not).
#include <cstddef>
#include <cstdint>

namespace exc::target {

struct HeapCallCount {
  std::uint32_t malloc = 0;    // malloc, _malloc_r, operator new
  std::uint32_t calloc = 0;
  std::uint32_t realloc = 0;
  std::uint32_t free = 0;      // free, _free_r, operator delete
  std::uint32_t memalign = 0;  // memalign, aligned_alloc, aligned operator new
  std::uint32_t total() const { return malloc + calloc + realloc + free + memalign; }
};

// Calls since reset.
HeapCallCount heap_calls();
// Ends start-up: heap_calls_after_start_up() counts from here.
void mark_start_up_over();
bool start_up_over();
// Calls since mark_start_up_over() (all zero before it).
HeapCallCount heap_calls_after_start_up();

// The heap's extent (linker script) and how far _sbrk has moved into it.
std::size_t heap_capacity_bytes();
std::size_t heap_break_bytes();

}  // namespace exc::target
