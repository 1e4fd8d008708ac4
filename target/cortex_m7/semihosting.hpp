#pragma once
// Arm semihosting (the "Semihosting for AArch32 and AArch64" specification): the image asks the
// debugger, here QEMU with -semihosting-config enable=on,target=native, to act for it on the host.
// The operations the start-up and the link need, called directly (BKPT 0xAB, the M-profile trap)
// rather than through newlib's file table, so the link's reads and writes are one trap each and
// report the host's answer unchanged. A trap blocks the emulated CPU until the host has answered, and
// under -icount costs one instruction however long the host takes (docs/target.md).
#include <cstddef>
#include <cstdint>

namespace exc::target::semihosting {

// Opens a host file; the mode is ISO C's fopen mode as the specification numbers them. Returns the
// handle, or -1 (errno_of_last_call() says why).
enum class OpenMode : std::uint32_t { read_binary = 1, write_binary = 5 };
int open(const char* path, OpenMode mode);
int close(int handle);

// Writes n bytes; returns how many of them were NOT written (0 on success).
std::size_t write(int handle, const void* bytes, std::size_t n);
// Reads at most n bytes, blocking until at least one is there (a FIFO: whatever the writer wrote so
// far) or the end of the file. Returns how many bytes were read: 0 is the end of the file (the FIFO's
// writer closed it); a negative value an error.
long read(int handle, void* bytes, std::size_t n);

// The host's errno of the last failed call.
int errno_of_last_call();

// Writes a NUL-terminated string to the debugger's console, with no buffering and no heap: for the
// fault handlers, which cannot trust newlib's stdio state.
void write_console(const char* text);

// The command line QEMU was given (-semihosting-config arg=...: the args joined by spaces), into
// buffer[0..capacity), NUL-terminated. Returns its length, or -1 when it does not fit or the host
// has none.
int command_line(char* buffer, std::size_t capacity);

// Ends the emulation with an exit status the host sees as QEMU's (SYS_EXIT_EXTENDED with
// ADP_Stopped_ApplicationExit). newlib's exit() does the same after flushing stdio; this is for
// the fault handlers.
[[noreturn]] void exit_with_status(int status);

}  // namespace exc::target::semihosting
