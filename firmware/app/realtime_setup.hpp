#pragma once
// What real-time firmware does before its first deadline, so the loop never pays for it later:
// lock every page in RAM (mlockall: no page-in or reclaim fault in the loop), touch a stack reserve
// (its first-touch faults happen now), and optionally ask for SCHED_FIFO. Each step reports
// whether the kernel granted it; a refusal is a warning, not an error (tests and containers
// without CAP_IPC_LOCK / CAP_SYS_NICE still run, and say so).
#include <cstddef>
#include <string>

namespace exc::app {

struct RealtimeRequest {
  bool lock_memory = true;
  std::size_t stack_prefault_bytes = 256 * 1024;  // deeper than any stack the loop reaches
  int fifo_priority = 0;                          // 0: keep the normal scheduler
};

struct RealtimeSetup {
  bool memory_locked = false;
  bool stack_prefaulted = false;
  bool fifo = false;
  std::string warnings;  // one line per refused step, empty when all were granted
};

RealtimeSetup prepare_realtime(const RealtimeRequest& request);

// Page faults of the calling thread so far (minor + major): the loop's count must not move.
long thread_page_faults();

}  // namespace exc::app
