#include "heap_calls.hpp"

#include <cerrno>
#include <reent.h>

// The linker script's heap: from the end of .bss to the stack's lowest word.
extern "C" char __heap_start[];
extern "C" char __heap_end[];

namespace exc::target {
namespace {

HeapCallCount g_calls;
HeapCallCount g_at_start_up_end;
bool g_start_up_over = false;
// Nesting depth of allocator calls: only the outermost is counted.
unsigned g_depth = 0;
char* g_break = __heap_start;

// Counts a call on entry when it is the outermost, and undoes the nesting on exit.
class CountedCall {
 public:
  explicit CountedCall(std::uint32_t HeapCallCount::*kind) {
    if (g_depth++ == 0) ++(g_calls.*kind);
  }
  ~CountedCall() { --g_depth; }
  CountedCall(const CountedCall&) = delete;
  CountedCall& operator=(const CountedCall&) = delete;
};

HeapCallCount difference(const HeapCallCount& now, const HeapCallCount& then) {
  HeapCallCount d;
  d.malloc = now.malloc - then.malloc;
  d.calloc = now.calloc - then.calloc;
  d.realloc = now.realloc - then.realloc;
  d.free = now.free - then.free;
  d.memalign = now.memalign - then.memalign;
  return d;
}

}  // namespace

HeapCallCount heap_calls() { return g_calls; }

void mark_start_up_over() {
  g_at_start_up_end = g_calls;
  g_start_up_over = true;
}

bool start_up_over() { return g_start_up_over; }

HeapCallCount heap_calls_after_start_up() {
  return g_start_up_over ? difference(g_calls, g_at_start_up_end) : HeapCallCount{};
}

std::size_t heap_capacity_bytes() { return static_cast<std::size_t>(__heap_end - __heap_start); }
std::size_t heap_break_bytes() { return static_cast<std::size_t>(g_break - __heap_start); }

}  // namespace exc::target

// The wrapped entry points (-Wl,--wrap=_malloc_r etc.): count, then call newlib's own (__real_...).
extern "C" {
void* __real__malloc_r(struct _reent*, std::size_t);
void* __real__calloc_r(struct _reent*, std::size_t, std::size_t);
void* __real__realloc_r(struct _reent*, void*, std::size_t);
void __real__free_r(struct _reent*, void*);
void* __real__memalign_r(struct _reent*, std::size_t, std::size_t);

void* __wrap__malloc_r(struct _reent* r, std::size_t n) {
  exc::target::CountedCall call(&exc::target::HeapCallCount::malloc);
  return __real__malloc_r(r, n);
}
void* __wrap__calloc_r(struct _reent* r, std::size_t count, std::size_t n) {
  exc::target::CountedCall call(&exc::target::HeapCallCount::calloc);
  return __real__calloc_r(r, count, n);
}
void* __wrap__realloc_r(struct _reent* r, void* p, std::size_t n) {
  exc::target::CountedCall call(&exc::target::HeapCallCount::realloc);
  return __real__realloc_r(r, p, n);
}
void __wrap__free_r(struct _reent* r, void* p) {
  exc::target::CountedCall call(&exc::target::HeapCallCount::free);
  __real__free_r(r, p);
}
void* __wrap__memalign_r(struct _reent* r, std::size_t alignment, std::size_t n) {
  exc::target::CountedCall call(&exc::target::HeapCallCount::memalign);
  return __real__memalign_r(r, alignment, n);
}

// newlib's allocator grows its arena through _sbrk; this one stays inside the linker script's heap.
// librdimon's (weak, so replaced) lets the heap grow up to the current stack pointer: into the
// stack's painted words, which would read as stack used.
void* _sbrk(std::ptrdiff_t increment) {
  using exc::target::g_break;
  if (increment > __heap_end - g_break || increment < __heap_start - g_break) {
    errno = ENOMEM;
    return reinterpret_cast<void*>(-1);
  }
  char* previous = g_break;
  g_break += increment;
  return previous;
}
}
