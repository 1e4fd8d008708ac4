#pragma once
// A person's Ctrl-C during a run: the first SIGINT asks the run to end at its next cycle boundary,
// so that its summary (marked interrupted, ok false), its closed log and its report are written;
// the handler is then the default again, so a second SIGINT ends the program at once.
#include <atomic>

namespace exc::sim {

// Non-zero once the first SIGINT came (LockstepOptions::interrupt).
const std::atomic<int>& run_interrupt();
// Installs the handler (once per program, before the runs).
void catch_run_interrupt();
// The exit status of a program ended by SIGINT (128 + 2), as a shell reports one.
inline constexpr int kInterruptedExit = 130;

}  // namespace exc::sim
