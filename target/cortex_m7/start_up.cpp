#include "start_up.hpp"

#include <cstdint>
#include <cstdlib>

#include "instruction_clock.hpp"
#include "semihosting.hpp"

extern "C" {
// newlib: librdimon opens the console's stdin/stdout/stderr; libc runs the constructors.
void initialise_monitor_handles();
void __libc_init_array();
void __libc_fini_array();
}

int exc_argc = 0;
char** exc_argv = nullptr;

namespace exc::target {
namespace {

// The command line's text, split in place into argv.
char g_command_line[1024];
char* g_arguments[kMaxArguments + 1];
char g_program_name[] = "image";

int split_command_line(char* text, char** arguments) {
  int count = 0;
  bool dropped = false;
  for (char* p = text; *p != '\0';) {
    while (*p == ' ') *p++ = '\0';
    if (*p == '\0') break;
    if (count == kMaxArguments) {
      dropped = true;
      break;
    }
    arguments[count++] = p;
    while (*p != '\0' && *p != ' ') ++p;
  }
  if (dropped) semihosting::write_console("start-up: more than 32 arguments on the command line; the rest dropped\n");
  arguments[count] = nullptr;
  return count;
}

volatile std::uint32_t& reg(std::uintptr_t address) { return *reinterpret_cast<volatile std::uint32_t*>(address); }

// Writes "name 0x0123abcd" for the fault report, without stdio.
char* append(char* out, const char* text) {
  while (*text != '\0') *out++ = *text++;
  return out;
}
char* append_hex(char* out, const char* name, std::uint32_t value) {
  out = append(out, name);
  out = append(out, " 0x");
  for (int shift = 28; shift >= 0; shift -= 4) *out++ = "0123456789abcdef"[(value >> shift) & 0xF];
  return out;
}

}  // namespace
}  // namespace exc::target

extern "C" void exc_prepare_runtime() {
  using namespace exc::target;
  initialise_monitor_handles();
  InstructionClock::start();
  const int length = semihosting::command_line(g_command_line, sizeof g_command_line);
  exc_argc = length > 0 ? split_command_line(g_command_line, g_arguments) : 0;
  if (exc_argc == 0) {  // no command line: argv[0] still names the program
    g_arguments[0] = g_program_name;
    g_arguments[1] = nullptr;
    exc_argc = 1;
  }
  exc_argv = g_arguments;
  std::atexit(__libc_fini_array);
  __libc_init_array();
}

// Names the exception (IPSR), the faulting instruction (the stacked PC) and the fault status
// registers, then ends the run: a fault must never look like a hang to the host.
extern "C" [[noreturn]] void exc_report_fault(const std::uint32_t* frame) {
  using namespace exc::target;
  std::uint32_t ipsr;
  asm volatile("mrs %0, ipsr" : "=r"(ipsr));
  static const char* const kNames[] = {"thread", "reset", "NMI", "HardFault", "MemManage", "BusFault", "UsageFault"};
  static char report[256];
  char* out = append(report, "fault: ");
  out = append(out, (ipsr & 0x1FF) < 7 ? kNames[ipsr & 0x1FF] : "exception");
  out = append_hex(out, ", ipsr", ipsr);
  out = append_hex(out, ", pc", frame[6]);
  out = append_hex(out, ", lr", frame[5]);
  out = append_hex(out, ", cfsr", reg(0xE000ED28));
  out = append_hex(out, ", hfsr", reg(0xE000ED2C));
  out = append_hex(out, ", mmfar", reg(0xE000ED34));
  out = append_hex(out, ", bfar", reg(0xE000ED38));
  out = append(out, "\n");
  *out = '\0';
  semihosting::write_console(report);
  semihosting::exit_with_status(kFaultExitStatus);
}

// The stacked frame is on the main or the process stack, as EXC_RETURN's bit 2 says.
extern "C" __attribute__((naked)) void exc_fault_handler() {
  asm volatile(
      "tst lr, #4\n"
      "ite eq\n"
      "mrseq r0, msp\n"
      "mrsne r0, psp\n"
      "b exc_report_fault\n");
}

extern "C" [[noreturn]] void exc_unexpected_interrupt_handler() {
  using namespace exc::target;
  std::uint32_t ipsr;
  asm volatile("mrs %0, ipsr" : "=r"(ipsr));
  static char report[64];
  char* out = append_hex(report, "fault: unexpected exception, ipsr", ipsr);
  out = append(out, "\n");
  *out = '\0';
  semihosting::write_console(report);
  semihosting::exit_with_status(kFaultExitStatus);
}
