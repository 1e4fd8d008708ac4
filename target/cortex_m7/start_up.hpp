#pragma once
// The image's start-up after the reset handler (reset_handler.S): the vector table, newlib's
// semihosting stdio, the instruction clock, the command line, the static constructors; and the fault
// handlers, which name the fault on the console and end the run with kFaultExitStatus.
//
// What runs before main, in order (docs/target.md, "Start-up"):
//   reset_handler.S: FPU on (CPACR, DSB, ISB), flush-to-zero, .data copied, .bss zeroed, stack painted
//   exc_prepare_runtime: stdin/stdout/stderr on the semihosting console, InstructionClock::start(),
//   argc/argv from the semihosting command line, atexit(static destructors), static constructors
//   main(argc, argv), then exit(its status): QEMU exits with that status.

namespace exc::target {

// The exit status of a run a fault handler ended (HardFault, MemManage, BusFault, UsageFault, an
// unexpected interrupt): the console says which and where.
inline constexpr int kFaultExitStatus = 125;

// The most arguments the command line is split into (argv[0] included); more are dropped with a
// warning on the console.
inline constexpr int kMaxArguments = 32;

}  // namespace exc::target

extern "C" {
// argc and argv for main, filled by exc_prepare_runtime (the reset handler passes them on).
extern int exc_argc;
extern char** exc_argv;
void exc_prepare_runtime();
}
