#pragma once
// A bare-metal image run on QEMU's emulated Cortex-M7 (mps2-an500), and the host's end of its link
// (docs/target.md): two FIFOs in a private temporary folder, one per direction, carrying the records
// of hal/link_records. The target opens them through semihosting with the paths the host put on its
// command line (--link-in PATH --link-out PATH, before the caller's arguments).
//
// Every wait is bounded by the timeout: the link's opening, each receive, a write into a full FIFO and
// the exit. A target that exits, faults or stops answering is an EmulatedTargetError naming the image,
// what the host was waiting for, the last record it received and the tail of what the target printed.
// The destructor kills and reaps QEMU and removes the folder: no zombie, no FIFO left behind.
//
// One thread at a time. The child QEMU gets SIGKILL if the thread that started it ends first.
#include <sys/types.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "hal/link_records.hpp"

namespace exc::sim {

class EmulatedTargetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct EmulatedTargetOptions {
  std::string image;                    // the ELF QEMU loads (-kernel)
  std::vector<std::string> arguments;   // the image's own, after --link-in PATH --link-out PATH
  double timeout_s = 60;                // the longest any one wait may take
  std::string qemu = "qemu-system-arm"; // searched in PATH unless it names a file
};

struct TargetRecord {
  std::uint8_t type = 0;
  std::vector<std::uint8_t> payload;
};

class EmulatedTarget {
 public:
  // Checks the image and QEMU, makes the folder and its FIFOs and starts QEMU. Returns without
  // waiting for the target: the first flush() or receive_until() waits for it to open the link.
  explicit EmulatedTarget(EmulatedTargetOptions options);
  ~EmulatedTarget();
  EmulatedTarget(const EmulatedTarget&) = delete;
  EmulatedTarget& operator=(const EmulatedTarget&) = delete;

  // The longest any one wait may take from now on (a test shortens it once the target is up).
  void set_timeout(double seconds) { timeout_s_ = seconds; }

  // Appends a record to the outbound buffer; payloads over the target's limit are the target's to refuse.
  void send(std::uint8_t type, const std::uint8_t* bytes, std::size_t n);
  void send(std::uint8_t type, const std::vector<std::uint8_t>& payload) { send(type, payload.data(), payload.size()); }
  // Writes the outbound buffer into the target's FIFO (waiting, within the timeout, while it is full).
  void flush();
  // Reads records until one of end_type (or of other_end_type, when given), which is the last of
  // those returned.
  std::vector<TargetRecord> receive_until(std::uint8_t end_type, int other_end_type = -1);

  // Waits for QEMU to end and returns the target's exit status (its semihosting exit code).
  int wait_for_exit();
  // Whether QEMU has ended (without waiting).
  bool exited();

  // What the target printed so far (QEMU's own messages share stderr with it).
  std::string printed_stdout() const;
  std::string printed_stderr() const;

  const std::string& image() const { return options_.image; }
  pid_t qemu_pid() const { return pid_; }
  const std::string& work_folder() const { return folder_; }
  // The QEMU command line, as run (for a bug report or a run by hand).
  const std::vector<std::string>& qemu_command() const { return command_; }
  std::uint64_t records_sent() const { return records_sent_; }
  std::uint64_t records_received() const { return decoder_.records(); }
  // "type 0x12, 40 bytes, record 7 received" or "no record received yet".
  std::string last_record_seen() const;

 private:
  [[noreturn]] void fail(const std::string& waiting_for, const std::string& what) const;
  // Reaps QEMU if it has ended; true then.
  bool reap();
  void open_link(const std::string& waiting_for);
  double remaining(double deadline) const;

  EmulatedTargetOptions options_;
  double timeout_s_;
  std::string folder_;
  std::string to_target_, from_target_, stdout_file_, stderr_file_;
  std::vector<std::string> command_;
  pid_t pid_ = -1;
  bool reaped_ = false;
  int wait_status_ = 0;
  int to_target_fd_ = -1;
  int from_target_fd_ = -1;

  std::vector<std::uint8_t> outbound_;
  std::uint64_t records_sent_ = 0;
  std::vector<std::uint8_t> inbound_;  // read from the FIFO, not yet decoded
  std::size_t inbound_begin_ = 0;
  std::vector<std::uint8_t> payload_storage_;
  hal::LinkRecordDecoder decoder_;
  int last_type_ = -1;
  std::size_t last_bytes_ = 0;
};

}  // namespace exc::sim
