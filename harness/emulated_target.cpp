#include "harness/emulated_target.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <thread>

namespace exc::sim {
namespace {

using Clock = std::chrono::steady_clock;

double now_s() { return std::chrono::duration<double>(Clock::now().time_since_epoch()).count(); }

std::string hex_type(int type) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02x", type & 0xFF);
  return text;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string tail(const std::string& text, std::size_t n) {
  return text.size() <= n ? text : "..." + text.substr(text.size() - n);
}

// The file QEMU is run from: as given when it names a path, else the first in PATH.
std::string find_program(const std::string& name) {
  if (name.find('/') != std::string::npos) return access(name.c_str(), X_OK) == 0 ? name : "";
  const char* path = std::getenv("PATH");
  std::stringstream folders(path != nullptr ? path : "/usr/bin:/bin");
  for (std::string folder; std::getline(folders, folder, ':');) {
    const std::string candidate = (folder.empty() ? "." : folder) + "/" + name;
    if (access(candidate.c_str(), X_OK) == 0) return candidate;
  }
  return "";
}

// -semihosting-config's values are comma-separated: a comma inside one is written twice.
std::string option_value(const std::string& text) {
  std::string out;
  for (char c : text) {
    out += c;
    if (c == ',') out += ',';
  }
  return out;
}

std::string base_name(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

// A write into a FIFO whose reader is gone fails with EPIPE and raises SIGPIPE, whose default action
// would end the host's whole process: blocked in this thread for the write, and a pending one taken.
ssize_t write_without_sigpipe(int fd, const std::uint8_t* bytes, std::size_t n) {
  sigset_t pipe_signal, previous;
  sigemptyset(&pipe_signal);
  sigaddset(&pipe_signal, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe_signal, &previous);
  const ssize_t written = write(fd, bytes, n);
  const int error = errno;
  if (written < 0 && error == EPIPE) {
    const timespec no_wait{0, 0};
    while (sigtimedwait(&pipe_signal, nullptr, &no_wait) == SIGPIPE) {
    }
  }
  pthread_sigmask(SIG_SETMASK, &previous, nullptr);
  errno = error;
  return written;
}

}  // namespace

EmulatedTarget::EmulatedTarget(EmulatedTargetOptions options)
    : options_(std::move(options)),
      timeout_s_(options_.timeout_s),
      payload_storage_(hal::kLinkRecordMaxPayload),
      decoder_(payload_storage_.data(), payload_storage_.size()) {
  const std::string who = "emulated target " + options_.image;
  if (!(options_.timeout_s > 0)) {
    throw EmulatedTargetError(who + ": timeout_s must be above 0 s (got " + std::to_string(options_.timeout_s) + ")");
  }
  if (access(options_.image.c_str(), R_OK) != 0) {
    throw EmulatedTargetError(who + ": the image cannot be read: " + std::strerror(errno));
  }
  const std::string qemu = find_program(options_.qemu);
  if (qemu.empty()) {
    throw EmulatedTargetError(who + ": '" + options_.qemu +
                              "' not found or not executable (Debian package qemu-system-arm; tools/install-deps test)");
  }
  for (const auto& argument : options_.arguments) {
    if (argument.empty() || argument.find_first_of(" \t\n") != std::string::npos) {
      throw EmulatedTargetError(who + ": argument '" + argument +
                                "' is empty or holds white space: QEMU hands the target its command line joined by spaces");
    }
  }

  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp != nullptr && *tmp != '\0' ? tmp : "/tmp") + "/exc-target-XXXXXX";
  if (pattern.find_first_of(" \t\n") != std::string::npos) {
    throw EmulatedTargetError(who + ": the temporary folder '" + pattern +
                              "' holds white space, which the target's command line cannot carry (set TMPDIR)");
  }
  if (mkdtemp(pattern.data()) == nullptr) {
    throw EmulatedTargetError(who + ": cannot make a temporary folder from '" + pattern + "': " + std::strerror(errno));
  }
  folder_ = pattern;
  to_target_ = folder_ + "/to_target";
  from_target_ = folder_ + "/from_target";
  stdout_file_ = folder_ + "/stdout";
  stderr_file_ = folder_ + "/stderr";

  int out_fd = -1, err_fd = -1;
  try {
    if (mkfifo(to_target_.c_str(), 0600) != 0 || mkfifo(from_target_.c_str(), 0600) != 0) {
      throw EmulatedTargetError(who + ": cannot make the link's FIFOs in " + folder_ + ": " + std::strerror(errno));
    }
    // The host's read end first, without waiting for a writer: the target's open for writing then
    // finds a reader and does not block.
    from_target_fd_ = ::open(from_target_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    out_fd = ::open(stdout_file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    err_fd = ::open(stderr_file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0600);
    if (from_target_fd_ < 0 || out_fd < 0 || err_fd < 0) {
      throw EmulatedTargetError(who + ": cannot open the link's files in " + folder_ + ": " + std::strerror(errno));
    }

    std::string config = "enable=on,target=native,arg=" + option_value(base_name(options_.image)) +
                         ",arg=--link-in,arg=" + option_value(to_target_) + ",arg=--link-out,arg=" +
                         option_value(from_target_);
    for (const auto& argument : options_.arguments) config += ",arg=" + option_value(argument);
    // No display, no default devices (monitor, serial, network on stdio); -icount shift=0: one
    // instruction per ns of virtual time, so the instruction clock counts instructions; sleep=off: an
    // idle CPU (WFI) jumps to its next timer instead of waiting in real time, so runs stay repeatable.
    command_ = {qemu, "-M", "mps2-an500", "-nodefaults", "-display", "none", "-icount", "shift=0,sleep=off",
                "-semihosting-config", config, "-kernel", options_.image};
    std::vector<char*> argv;
    for (auto& part : command_) argv.push_back(part.data());
    argv.push_back(nullptr);

    const pid_t parent = getpid();
    pid_ = fork();
    if (pid_ < 0) throw EmulatedTargetError(who + ": cannot start QEMU (fork): " + std::strerror(errno));
    if (pid_ == 0) {
      // The child: only async-signal-safe calls until exec.
      prctl(PR_SET_PDEATHSIG, SIGKILL);
      if (getppid() != parent) _exit(127);
      const int null_fd = ::open("/dev/null", O_RDONLY);
      if (null_fd >= 0) dup2(null_fd, 0);
      dup2(out_fd, 1);
      dup2(err_fd, 2);
      execv(argv[0], argv.data());
      const char message[] = "emulated target: exec of QEMU failed\n";
      (void)!write(2, message, sizeof message - 1);
      _exit(127);
    }
    ::close(out_fd);
    ::close(err_fd);
  } catch (...) {
    if (out_fd >= 0) ::close(out_fd);
    if (err_fd >= 0) ::close(err_fd);
    if (from_target_fd_ >= 0) ::close(from_target_fd_);
    ::unlink(to_target_.c_str());
    ::unlink(from_target_.c_str());
    ::unlink(stdout_file_.c_str());
    ::unlink(stderr_file_.c_str());
    ::rmdir(folder_.c_str());
    throw;
  }
}

EmulatedTarget::~EmulatedTarget() {
  if (to_target_fd_ >= 0) ::close(to_target_fd_);
  if (from_target_fd_ >= 0) ::close(from_target_fd_);
  if (pid_ > 0 && !reaped_) {
    // SIGKILL: a QEMU whose CPU waits in a semihosting read holds its main loop's lock, so a SIGTERM
    // might wait for it; QEMU leaves nothing behind that needs an orderly end.
    ::kill(pid_, SIGKILL);
    int status = 0;
    while (waitpid(pid_, &status, 0) < 0 && errno == EINTR) {
    }
  }
  ::unlink(to_target_.c_str());
  ::unlink(from_target_.c_str());
  ::unlink(stdout_file_.c_str());
  ::unlink(stderr_file_.c_str());
  ::rmdir(folder_.c_str());
}

double EmulatedTarget::remaining(double deadline) const { return deadline - now_s(); }

bool EmulatedTarget::reap() {
  if (reaped_) return true;
  int status = 0;
  const pid_t r = waitpid(pid_, &status, WNOHANG);
  if (r == pid_) {
    reaped_ = true;
    wait_status_ = status;
  }
  return reaped_;
}

bool EmulatedTarget::exited() { return reap(); }

std::string EmulatedTarget::printed_stdout() const { return read_file(stdout_file_); }
std::string EmulatedTarget::printed_stderr() const { return read_file(stderr_file_); }

std::string EmulatedTarget::last_record_seen() const {
  if (last_type_ < 0) return "no record received yet";
  return "type " + hex_type(last_type_) + ", " + std::to_string(last_bytes_) + " bytes, record " +
         std::to_string(decoder_.records()) + " received";
}

void EmulatedTarget::fail(const std::string& waiting_for, const std::string& what) const {
  std::string message = "emulated target " + options_.image + ": " + what + " while the host waited for " +
                        waiting_for + "; last record seen: " + last_record_seen();
  const std::string err = printed_stderr(), out = printed_stdout();
  message += "; its stderr: " + (err.empty() ? std::string("(nothing)") : "'" + tail(err, 1500) + "'");
  message += "; its stdout: " + (out.empty() ? std::string("(nothing)") : "'" + tail(out, 1500) + "'");
  throw EmulatedTargetError(message);
}

namespace {
std::string describe_end(int status) {
  if (WIFEXITED(status)) return "the target exited with status " + std::to_string(WEXITSTATUS(status));
  if (WIFSIGNALED(status)) return "QEMU was killed by signal " + std::to_string(WTERMSIG(status));
  return "QEMU ended";
}
}  // namespace

void EmulatedTarget::open_link(const std::string& waiting_for) {
  if (to_target_fd_ >= 0) return;
  const double deadline = now_s() + timeout_s_;
  // The target opens its inbound FIFO for reading and blocks there until a writer comes; an open
  // for writing without waiting succeeds once it is there (ENXIO before).
  for (;;) {
    to_target_fd_ = ::open(to_target_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC);
    if (to_target_fd_ >= 0) return;
    if (errno != ENXIO) fail(waiting_for, std::string("cannot open the link's FIFO: ") + std::strerror(errno));
    if (reap()) fail(waiting_for, describe_end(wait_status_) + " before it opened the link");
    if (remaining(deadline) <= 0) {
      fail(waiting_for, "timed out after " + std::to_string(timeout_s_) +
                            " s: the target did not open its end of the link (--link-in)");
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

void EmulatedTarget::send(std::uint8_t type, const std::uint8_t* bytes, std::size_t n) {
  if (n > hal::kLinkRecordMaxPayload) {
    throw EmulatedTargetError("emulated target " + options_.image + ": a record of type " + hex_type(type) + " with " +
                              std::to_string(n) + " bytes is over the link's limit of " +
                              std::to_string(hal::kLinkRecordMaxPayload));
  }
  const std::size_t at = outbound_.size();
  outbound_.resize(at + hal::link_record_bytes(n));
  hal::encode_link_record(type, bytes, n, outbound_.data() + at, outbound_.size() - at);
  ++records_sent_;
}

void EmulatedTarget::flush() {
  const std::string waiting_for = "the target to read " + std::to_string(outbound_.size()) + " bytes of records";
  open_link(waiting_for);
  const double deadline = now_s() + timeout_s_;
  std::size_t done = 0;
  while (done < outbound_.size()) {
    const ssize_t n = write_without_sigpipe(to_target_fd_, outbound_.data() + done, outbound_.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno == EPIPE) {
      for (int i = 0; i < 100 && !reap(); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(10));
      fail(waiting_for, reaped_ ? describe_end(wait_status_) : "the target closed its end of the link");
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) fail(waiting_for, std::string("write: ") + std::strerror(errno));
    // The FIFO is full: wait for the target to read, or to end.
    const double left = remaining(deadline);
    if (left <= 0) fail(waiting_for, "timed out after " + std::to_string(timeout_s_) + " s (the FIFO stayed full)");
    if (reap()) fail(waiting_for, describe_end(wait_status_));
    pollfd p{to_target_fd_, POLLOUT, 0};
    poll(&p, 1, static_cast<int>(std::min(left, 0.1) * 1000) + 1);
  }
  outbound_.clear();
}

std::vector<TargetRecord> EmulatedTarget::receive_until(std::uint8_t end_type, int other_end_type) {
  const std::string waiting_for = "a record of type " + hex_type(end_type) +
                                  (other_end_type >= 0 ? " or " + hex_type(static_cast<std::uint8_t>(other_end_type)) : std::string()) +
                                  " (the end of a batch)";
  open_link(waiting_for);
  std::vector<TargetRecord> batch;
  const double deadline = now_s() + timeout_s_;
  std::uint8_t chunk[65536];
  for (;;) {
    while (inbound_begin_ < inbound_.size()) {
      const auto step = decoder_.feed(inbound_.data() + inbound_begin_, inbound_.size() - inbound_begin_);
      inbound_begin_ += step.consumed;
      if (step.event == hal::LinkRecordDecoder::Event::error) {
        const auto& f = decoder_.fault();
        fail(waiting_for, std::string("the target's records broke the framing: ") + hal::to_string(f.error) +
                              " at byte " + std::to_string(f.offset) + " of the stream (found " +
                              std::to_string(f.found) + ", limit or computed CRC " + std::to_string(f.limit) + ")");
      }
      if (step.event == hal::LinkRecordDecoder::Event::record) {
        const hal::LinkRecordView v = decoder_.record();
        batch.push_back({v.type, std::vector<std::uint8_t>(v.payload, v.payload + v.payload_bytes)});
        last_type_ = v.type;
        last_bytes_ = v.payload_bytes;
        if (v.type == end_type || v.type == other_end_type) {
          inbound_.erase(inbound_.begin(), inbound_.begin() + static_cast<std::ptrdiff_t>(inbound_begin_));
          inbound_begin_ = 0;
          return batch;
        }
      }
    }
    inbound_.clear();
    inbound_begin_ = 0;

    const ssize_t n = ::read(from_target_fd_, chunk, sizeof chunk);
    if (n > 0) {
      inbound_.assign(chunk, chunk + n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) fail(waiting_for, std::string("read: ") + std::strerror(errno));
    // Nothing to read: QEMU ended (its write end closed, so n == 0 for good), or the target is busy.
    if (reap()) {
      std::string what = describe_end(wait_status_);
      if (decoder_.mid_record()) {
        what += ", cutting a record short (" + std::to_string(decoder_.partial_bytes()) + " bytes of it received)";
      }
      fail(waiting_for, what);
    }
    const double left = remaining(deadline);
    if (left <= 0) fail(waiting_for, "timed out after " + std::to_string(timeout_s_) + " s");
    if (n == 0) {
      // The writer closed but QEMU runs on (the target closed the link): poll() would return at once.
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    } else {
      pollfd p{from_target_fd_, POLLIN, 0};
      poll(&p, 1, static_cast<int>(std::min(left, 0.1) * 1000) + 1);
    }
  }
}

int EmulatedTarget::wait_for_exit() {
  const std::string waiting_for = "the target to exit";
  const double deadline = now_s() + timeout_s_;
  std::uint8_t chunk[65536];
  while (!reap()) {
    // Keep its FIFO drained, so a target still writing is not stuck on a full one.
    const ssize_t n = ::read(from_target_fd_, chunk, sizeof chunk);
    if (n > 0) inbound_.insert(inbound_.end(), chunk, chunk + n);
    if (remaining(deadline) <= 0) fail(waiting_for, "timed out after " + std::to_string(timeout_s_) + " s");
    if (n <= 0) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  if (!WIFEXITED(wait_status_)) fail(waiting_for, describe_end(wait_status_));
  return WEXITSTATUS(wait_status_);
}

}  // namespace exc::sim
