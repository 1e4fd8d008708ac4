#include "allocation_counter.hpp"

#include <cstdlib>
#include <malloc.h>

namespace {
thread_local std::size_t t_allocations = 0;
inline void note() { ++t_allocations; }
// The count is read through a volatile access: the compiler takes malloc for a function that touches
// no memory of ours, so a plain read after a malloc may reuse the value read before it (it does at
// -O2 when the sanitizer's hook, not our malloc, does the counting).
std::size_t allocations_so_far() { return *static_cast<volatile std::size_t*>(&t_allocations); }
}  // namespace

#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
// Under AddressSanitizer (or ThreadSanitizer) malloc belongs to the sanitizer's allocator, and
// defining it here as well breaks the sanitizer's start-up; its allocation hook sees every
// allocation (new, malloc, calloc, realloc, the aligned ones) instead. GCC ships the runtime but not
// its header, so the hook's entry point (a stable C interface of the sanitizer runtime) is declared
// here.
extern "C" int __sanitizer_install_malloc_and_free_hooks(void (*)(const volatile void*, size_t),
                                                         void (*)(const volatile void*));

namespace {
void on_allocation(const volatile void*, size_t) { note(); }
void on_free(const volatile void*) {}
const int g_hooks_installed = __sanitizer_install_malloc_and_free_hooks(on_allocation, on_free);
}  // namespace
#else
// glibc exports its allocator under __libc_* names; defining malloc & co. here interposes them for
// the whole process while still using glibc's allocator underneath.
extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
}

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
#endif

namespace exc::app {

AllocationCounter::AllocationCounter() : start_(allocations_so_far()) {}
AllocationCounter::~AllocationCounter() = default;
std::size_t AllocationCounter::count() const { return allocations_so_far() - start_; }

bool allocation_counting_works() {
  AllocationCounter c;
  void* volatile p = std::malloc(16);
  std::free(p);
  return c.count() == 1;
}

}  // namespace exc::app
