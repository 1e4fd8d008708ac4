#include "app/realtime_setup.hpp"

#include <sched.h>
#include <sys/mman.h>
#include <sys/resource.h>

#include <cerrno>
#include <cstring>

namespace exc::app {
namespace {

// Writes every page of a stack reserve. noinline and the volatile store keep the compiler from
// eliding the array (it must really be on the stack, below the caller's frame).
__attribute__((noinline)) void touch_stack(std::size_t bytes) {
  constexpr std::size_t kChunk = 16 * 1024;
  volatile unsigned char reserve[kChunk];
  for (std::size_t i = 0; i < kChunk; i += 4096) reserve[i] = 0;
  const unsigned char sink = reserve[0];  // a volatile read: the array is used
  (void)sink;
  if (bytes > kChunk) touch_stack(bytes - kChunk);
}

}  // namespace

RealtimeSetup prepare_realtime(const RealtimeRequest& request) {
  RealtimeSetup s;
  if (request.lock_memory) {
    if (mlockall(MCL_CURRENT | MCL_FUTURE) == 0) {
      s.memory_locked = true;
    } else {
      s.warnings += std::string("mlockall refused (") + std::strerror(errno) + "): page faults may add latency\n";
    }
  }
  if (request.stack_prefault_bytes > 0) {
    touch_stack(request.stack_prefault_bytes);
    s.stack_prefaulted = true;
  }
  if (request.fifo_priority > 0) {
    sched_param p{};
    p.sched_priority = request.fifo_priority;
    if (sched_setscheduler(0, SCHED_FIFO, &p) == 0) {
      s.fifo = true;
    } else {
      s.warnings += std::string("SCHED_FIFO refused (") + std::strerror(errno) + "): running at normal priority\n";
    }
  }
  return s;
}

long thread_page_faults() {
  rusage u{};
  getrusage(RUSAGE_THREAD, &u);
  return u.ru_minflt + u.ru_majflt;
}

}  // namespace exc::app
