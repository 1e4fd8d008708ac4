#pragma once
// Counts heap allocations made by the calling thread while a counter is alive: what a run reports as
// its heap allocations in the loop (harness/lockstep_run.cpp) and what the tests hold the real-time
// path to (zero). malloc, calloc, realloc, aligned_alloc, posix_memalign and memalign are interposed
// in allocation_counter.cpp, so operator new, Eigen's aligned allocator and any C library call that
// allocates are all seen. Link the object library exc_allocation_counter into the executable (an
// interposed malloc must be in it, not in a shared library).
#include <cstddef>

#ifdef EIGEN_RUNTIME_NO_MALLOC
#include <Eigen/Core>
#endif

namespace exc::app {

class AllocationCounter {
 public:
  AllocationCounter();
  ~AllocationCounter();
  AllocationCounter(const AllocationCounter&) = delete;
  AllocationCounter& operator=(const AllocationCounter&) = delete;
  // Allocations by this thread since construction.
  std::size_t count() const;

 private:
  std::size_t start_;
};

// Forbids Eigen heap use for its lifetime (test builds define EIGEN_RUNTIME_NO_MALLOC, so a
// dynamic-size temporary inside the scope fails an assertion at the line that made it).
class EigenNoMallocScope {
 public:
#ifdef EIGEN_RUNTIME_NO_MALLOC
  EigenNoMallocScope() { Eigen::internal::set_is_malloc_allowed(false); }
  ~EigenNoMallocScope() { Eigen::internal::set_is_malloc_allowed(true); }
#else
  // Release builds have no Eigen malloc switch; the scope still compiles (and is not "unused").
  EigenNoMallocScope() {}
  ~EigenNoMallocScope() {}
#endif
  EigenNoMallocScope(const EigenNoMallocScope&) = delete;
  EigenNoMallocScope& operator=(const EigenNoMallocScope&) = delete;
};

// Whether the malloc interposition is active in this executable (a sanity check for the figures and
// tests that rely on it: an allocation must be seen).
bool allocation_counting_works();

}  // namespace exc::app
