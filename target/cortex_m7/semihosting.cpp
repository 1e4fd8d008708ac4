#include "semihosting.hpp"

namespace exc::target::semihosting {
namespace {

// Operation numbers (the specification's SYS_* names).
enum Operation : std::uint32_t {
  sys_open = 0x01,
  sys_close = 0x02,
  sys_write0 = 0x04,
  sys_write = 0x05,
  sys_read = 0x06,
  sys_errno = 0x13,
  sys_get_cmdline = 0x15,
  sys_exit = 0x18,
  sys_exit_extended = 0x20,
};
constexpr std::uint32_t kApplicationExit = 0x20026;  // ADP_Stopped_ApplicationExit

// r0 the operation, r1 its argument (mostly a pointer to a block of words); the answer in r0. The
// "memory" clobber: the host reads and writes the blocks the argument points to.
std::int32_t trap(std::uint32_t operation, const void* argument) {
  register std::uint32_t r0 asm("r0") = operation;
  register const void* r1 asm("r1") = argument;
  asm volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
  return static_cast<std::int32_t>(r0);
}

std::uint32_t word(const void* pointer) { return reinterpret_cast<std::uintptr_t>(pointer); }

std::size_t length_of(const char* text) {
  std::size_t n = 0;
  while (text[n] != '\0') ++n;
  return n;
}

}  // namespace

int open(const char* path, OpenMode mode) {
  const std::uint32_t block[3] = {word(path), static_cast<std::uint32_t>(mode), length_of(path)};
  return trap(sys_open, block);
}

int close(int handle) {
  const std::uint32_t block[1] = {static_cast<std::uint32_t>(handle)};
  return trap(sys_close, block);
}

std::size_t write(int handle, const void* bytes, std::size_t n) {
  const std::uint32_t block[3] = {static_cast<std::uint32_t>(handle), word(bytes), n};
  return static_cast<std::uint32_t>(trap(sys_write, block));
}

long read(int handle, void* bytes, std::size_t n) {
  const std::uint32_t block[3] = {static_cast<std::uint32_t>(handle), word(bytes), n};
  const std::int32_t not_read = trap(sys_read, block);
  if (not_read < 0 || static_cast<std::size_t>(not_read) > n) return -1;
  return static_cast<long>(n - static_cast<std::size_t>(not_read));
}

int errno_of_last_call() { return trap(sys_errno, nullptr); }

void write_console(const char* text) { trap(sys_write0, text); }

int command_line(char* buffer, std::size_t capacity) {
  if (capacity == 0) return -1;
  std::uint32_t block[2] = {word(buffer), capacity};
  if (trap(sys_get_cmdline, block) != 0) return -1;
  const std::uint32_t n = block[1];  // the host's length, without the terminating NUL
  if (n >= capacity) return -1;
  buffer[n] = '\0';
  return static_cast<int>(n);
}

void exit_with_status(int status) {
  const std::uint32_t block[2] = {kApplicationExit, static_cast<std::uint32_t>(status)};
  trap(sys_exit_extended, block);
  // A host without the extended exit: the plain one, which can only say "stopped" (status 0) or not.
  trap(sys_exit, reinterpret_cast<const void*>(status == 0 ? kApplicationExit : 0x20023));
  for (;;) {
  }
}

}  // namespace exc::target::semihosting
