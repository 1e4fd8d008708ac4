#pragma once
// The helper programs a program runs (excavator-log report, plot-run, the chart scripts). Standard
// output to a file or a pipe is block-buffered: a helper started while part of a table was still in
// this program's buffer printed its line into the middle of the table. run_helper flushes first, so a
// helper's lines follow everything printed before them.
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

namespace exc::output {

// argv[0] found on PATH when it has no '/'. Waits for the helper; its exit status, 127 when it could
// not run, 128 when a signal ended it.
inline int run_helper(const std::vector<std::string>& argv) {
  std::cout.flush();
  std::fflush(nullptr);  // every C stream (stdout, stderr and any other open one): the child inherits none half-written
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t pid = fork();
  if (pid < 0) return 127;
  if (pid == 0) {
    execvp(args[0], args.data());
    std::fprintf(stderr, "cannot run %s\n", args[0]);
    _exit(127);
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0)
    if (errno != EINTR) return 127;
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128;
}

// The command line as a person would type it (for an error message).
inline std::string command_text(const std::vector<std::string>& argv) {
  std::string text;
  for (const std::string& a : argv) text += (text.empty() ? "" : " ") + a;
  return text;
}

}  // namespace exc::output
