#include "run_interrupt.hpp"

#include <signal.h>
#include <unistd.h>

#include <cstring>

namespace exc::sim {

namespace {

std::atomic<int> g_interrupt{0};

extern "C" void on_first_interrupt(int) {
  g_interrupt.store(1);
  // Async-signal-safe: write(2) only. SA_RESETHAND has made the next SIGINT the default's.
  static const char kText[] =
      "\nexcavator-sim: interrupted: the run ends at the next cycle; its summary, log and report are written "
      "(Ctrl-C again aborts)\n";
  const ssize_t ignored = ::write(STDERR_FILENO, kText, sizeof kText - 1);
  (void)ignored;
}

}  // namespace

const std::atomic<int>& run_interrupt() { return g_interrupt; }

void catch_run_interrupt() {
  struct sigaction action;
  std::memset(&action, 0, sizeof action);
  action.sa_handler = on_first_interrupt;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESETHAND | SA_RESTART;
  ::sigaction(SIGINT, &action, nullptr);
}

}  // namespace exc::sim
