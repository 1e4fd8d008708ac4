#pragma once
// The programs' output files. An std::ofstream that failed to open swallows every write, so a
// summary sent to a directory that does not exist was lost while the program exited 0. These throw
// std::runtime_error naming the file instead; the programs' handlers turn that into a non-zero exit.
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <stdexcept>
#include <string>

namespace exc::output {

namespace detail {
inline std::runtime_error cannot_write(const std::filesystem::path& path, int error) {
  return std::runtime_error(path.string() + ": cannot write" + (error != 0 ? std::string(" (") + std::strerror(error) + ")" : ""));
}
}  // namespace detail

// A file opened for writing (truncated), or an exception naming it.
inline std::ofstream open_file(const std::filesystem::path& path) {
  errno = 0;
  std::ofstream f(path);
  if (!f) throw detail::cannot_write(path, errno);
  return f;
}

// What has been written so far on its way to the file (a shard keeps each case it finished), or an
// exception naming it when a write failed (disk full).
inline void flush_file(std::ofstream& f, const std::filesystem::path& path) {
  errno = 0;
  f.flush();
  if (!f) throw detail::cannot_write(path, errno);
}

// A file written in pieces, flushed, checked and closed; throws when any write failed.
inline void finish_file(std::ofstream& f, const std::filesystem::path& path) {
  flush_file(f, path);
  f.close();
  if (!f) throw detail::cannot_write(path, errno);
}

// The whole of `text` in the file at `path`, or an exception naming it.
inline void write_file(const std::filesystem::path& path, const std::string& text) {
  std::ofstream f = open_file(path);
  f << text;
  finish_file(f, path);
}

namespace detail {
inline const char* g_stdout_program = "program";
inline int g_stdout_status = 2;
inline void stdout_at_exit() {
  std::cout.flush();
  errno = 0;
  const bool lost = !std::cout || std::fflush(stdout) != 0 || std::ferror(stdout);
  if (!lost) return;
  const int error = errno;
  std::fprintf(stderr, "%s: standard output: cannot write%s%s%s\n", g_stdout_program, error != 0 ? " (" : "",
               error != 0 ? std::strerror(error) : "", error != 0 ? ")" : "");
  _exit(g_stdout_status);  // from an exit handler: the status must change, and nothing is left to flush
}
}  // namespace detail

// A program's output on stdout (a table, a configuration, -o -) lost to a full disk or a closed
// descriptor must not end in exit 0. Called once at the start of main: at exit, stdout is flushed
// and a failed write is named on stderr and turns the exit status into `status` (as coreutils do).
inline void check_stdout_at_exit(const char* program, int status = 2) {
  detail::g_stdout_program = program;
  detail::g_stdout_status = status;
  std::atexit(detail::stdout_at_exit);
}

}  // namespace exc::output
