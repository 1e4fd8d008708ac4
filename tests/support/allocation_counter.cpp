#include "allocation_counter.hpp"

#include <cstdlib>
#include <malloc.h>

// glibc exports its allocator under __libc_* names; defining malloc & co. here interposes them for
// the whole test process while still using glibc's allocator underneath.
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
}

namespace {
thread_local std::size_t t_allocations = 0;
inline void note() { ++t_allocations; }
}  // namespace

extern "C" {
void* malloc(size_t n) {
  note();
  return __libc_malloc(n);
}
void* calloc(size_t a, size_t b) {
  note();
  return __libc_calloc(a, b);
}
void* realloc(void* p, size_t n) {
  note();
  return __libc_realloc(p, n);
}
void* memalign(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
void* aligned_alloc(size_t align, size_t n) {
  note();
  return __libc_memalign(align, n);
}
int posix_memalign(void** out, size_t align, size_t n) {
  note();
  void* p = __libc_memalign(align, n);
  if (p == nullptr) return 12;  // ENOMEM
  *out = p;
  return 0;
}
}

namespace exc::test {

AllocationCounter::AllocationCounter() : start_(t_allocations) {}
AllocationCounter::~AllocationCounter() = default;
std::size_t AllocationCounter::count() const { return t_allocations - start_; }

bool allocation_counting_works() {
  AllocationCounter c;
  void* volatile p = std::malloc(16);
  std::free(p);
  return c.count() == 1;
}

}  // namespace exc::test
